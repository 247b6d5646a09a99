"""The perturbed trials a plan is replayed on: the sizes of their errors
(:class:`Perturbation`), the trials themselves (:class:`VerifySettings`:
screening, held-out and untruncated) and the rollout kernel's step
(:class:`KernelSettings`), with the readers of the flat dicts that callers
not yet switched to the typed settings still pass."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.planning.core.settings.defaults import schema_value

TRUNCATE_SIGMA = 2.0  # normal perturbations are drawn within +-2 sigma; the planner's box is as wide
HOLDOUT_STREAM = 4_001  # salt of the held-out trials' seed: a stream no screen or selection draws from
UNTRUNCATED_STREAM = 4_002  # salt of the untruncated trials' seed: no selection or held-out trial draws from it


@dataclass(frozen=True)
class Perturbation:
    """Sizes of the errors each trial draws (``verify`` section): orientation
    (normal, deg), centroid height (uniform half-width, mm), friction (normal)
    and every pin's position (uniform half-width, mm)."""

    theta_sigma: float = schema_value("verify", "theta_sigma")
    y_halfwidth: float = schema_value("verify", "y_halfwidth")
    mu_sigma: float = schema_value("verify", "mu_sigma")
    pin_halfwidth: float = schema_value("verify", "pin_halfwidth")

    @classmethod
    def from_section(cls, section) -> "Perturbation":
        """The sizes of a ``verify``-style section (``theta_sigma``,
        ``y_halfwidth``, ``mu_sigma``, ``pin_halfwidth``; the schema's where
        one is absent; other keys ignored), values as given."""
        sizes = dict(dataclasses.asdict(cls()), **(section or {}))
        return cls(sizes["theta_sigma"], sizes["y_halfwidth"], sizes["mu_sigma"], sizes["pin_halfwidth"])


@dataclass(frozen=True)
class VerifySettings:
    """The perturbed trials a plan is replayed on: ``trials`` per resting state,
    the perturbation box's ``corners``, the ``seed``, and ``holdout_trials``
    (``None``: as many as ``trials``) for the held-out trials that certify it.

    ``truncate_sigma`` is where the normals of theta and of a single friction
    are cut (``None``: not cut, the tails' trials of :meth:`untruncated`);
    ``holdout`` says which trials these are, for the record: ``None`` the
    trials that screen and select plans, ``True`` the held-out ones
    (:meth:`held_out`), ``False`` the untruncated ones."""

    trials: int = schema_value("verify", "trials")
    corners: bool = schema_value("verify", "corners")
    seed: int = schema_value("verify", "seed")
    holdout_trials: int | None = schema_value("verify", "holdout_trials")
    perturbation: Perturbation = field(default_factory=Perturbation)
    truncate_sigma: float | None = TRUNCATE_SIGMA
    holdout: bool | None = None

    @classmethod
    def from_section(cls, section) -> "VerifySettings":
        """The trials of a ``verify`` section, whole or partial (the schema's
        defaults for what it leaves out; the claim's keys ``required``,
        ``confidence`` and ``rule`` ignored), values as given. Also reads the
        flat dict of :meth:`as_dict` back (``truncate_sigma``, ``holdout``)."""
        d = dict(cls().as_dict(), **(section or {}))
        return cls(d["trials"], d["corners"], d["seed"], d["holdout_trials"], Perturbation.from_section(d),
                   d.get("truncate_sigma", TRUNCATE_SIGMA), d.get("holdout"))

    def held_out(self, attempt: int = 0) -> "VerifySettings":
        """The settings of the held-out trials that certify a plan.

        The search screens and selects plans on these trials (seed ``seed``);
        the plan it picks is certified on fresh trials from a seed derived
        from ``(seed, HOLDOUT_STREAM, attempt)``, which no screen or selection
        draws from, ``holdout_trials`` per state (default: as many as
        ``trials``; fewer is refused with a one-line :class:`PinfeedError`).
        The same settings give the same held-out trials. The box corners are
        replayed again (they are not random)."""
        n = int(self.trials) if self.holdout_trials is None else int(self.holdout_trials)
        if n < int(self.trials):
            raise PinfeedError(f"verify.holdout_trials ({n}) must be at least verify.trials ({self.trials}): "
                               "the trials that certify a plan may not be fewer than those that chose it")
        seed = int(np.random.SeedSequence([int(self.seed), HOLDOUT_STREAM, int(attempt)]).generate_state(1)[0])
        return dataclasses.replace(self, trials=n, seed=seed, holdout=True)

    def untruncated(self, trials_per_state: int) -> "VerifySettings":
        """The settings of the untruncated trials (the tails,
        :mod:`pipeline.planning.claims.tails`): ``trials_per_state`` random
        trials per initial state (no box corners: the box has no edge),
        normals not cut, seed derived from ``(seed, UNTRUNCATED_STREAM)``,
        which neither the selection nor the held-out trials draw from."""
        seed = int(np.random.SeedSequence([int(self.seed), UNTRUNCATED_STREAM]).generate_state(1)[0])
        return dataclasses.replace(self, trials=int(trials_per_state), seed=seed, corners=False,
                                   truncate_sigma=None, holdout=False)

    def as_dict(self) -> dict:
        """The flat dict a verification record keeps under ``settings``: the
        trials, corners, seed, ``holdout_trials`` and the perturbation sizes;
        then ``truncate_sigma`` when the normals are not cut at
        ``TRUNCATE_SIGMA`` and ``holdout`` when it is set."""
        out = {"trials": self.trials, "corners": self.corners, "seed": self.seed,
               "holdout_trials": self.holdout_trials, **dataclasses.asdict(self.perturbation)}
        if self.truncate_sigma != TRUNCATE_SIGMA:
            out["truncate_sigma"] = self.truncate_sigma
        if self.holdout is not None:
            out["holdout"] = self.holdout
        return out


def as_verify_settings(settings) -> VerifySettings:
    """``settings`` as a :class:`VerifySettings`: one as it is, ``None`` as the
    schema's, and a flat dict of :meth:`VerifySettings.as_dict` keys (whole or
    partial) read with :meth:`VerifySettings.from_section`: the dicts that
    callers not yet switched to the typed settings still pass."""
    if isinstance(settings, VerifySettings):
        return settings
    return VerifySettings.from_section(settings)


@dataclass(frozen=True)
class KernelSettings:
    """The rollout kernel's integrator step (``sweep.kernel``): the largest
    step ``ds_max`` (units of a) and the tolerance ``tol``; ``None``: the
    kernel's own default."""

    ds_max: float | None = None
    tol: float | None = None

    @classmethod
    def from_section(cls, section) -> "KernelSettings":
        """The step of a ``sweep.kernel`` section (``None`` or ``{}``: the kernel's defaults)."""
        section = section or {}
        return cls(section.get("ds_max"), section.get("tol"))

    def with_defaults(self, ds_max: float, tol: float) -> "KernelSettings":
        """The same step with ``ds_max`` and ``tol`` where it leaves them to the kernel."""
        return KernelSettings(ds_max if self.ds_max is None else self.ds_max, tol if self.tol is None else self.tol)

    def as_kwargs(self) -> dict:
        """The keywords of a rollout: ``ds_max`` and ``tol``, those that are set."""
        return {k: v for k, v in (("ds_max", self.ds_max), ("tol", self.tol)) if v is not None}


def as_kernel_settings(kernel) -> KernelSettings:
    """``kernel`` as a :class:`KernelSettings`: one as it is, ``None`` as the
    kernel's defaults, a dict (``ds_max``, ``tol``; other keys ignored) read
    with :meth:`KernelSettings.from_section`: the dicts that callers not yet
    switched to the typed settings still pass."""
    if isinstance(kernel, KernelSettings):
        return kernel
    return KernelSettings.from_section(kernel)

