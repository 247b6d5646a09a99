"""The planner's settings, built once from the validated config.

:class:`PlannerSettings` (:meth:`PlannerSettings.from_config`, the one place
a config's ``planner``, ``verify``, ``speed`` and ``sweep`` sections are
read for planning) is a frozen tree of typed parts: :class:`Friction` (the
friction a plan must work for: a value or a range, its sigma and the
truncation both widenings use), :class:`Perturbation` and
:class:`VerifySettings` (the trials), :class:`ClaimSettings` (tolerance,
required share, confidence, rule), :class:`SearchSettings` (pins, depth,
limits in d, model, belt, moving pins; the rollout kernel's step,
:class:`KernelSettings`) and :class:`SpeedSettings` (with the uniform box
of its trials, :class:`SpeedPerturbation`). Beside them, the settings of
the stages that stand on plans: :class:`LayoutSettings` (``layout``) and
:class:`DesignSettings` (``design``). Every default comes from
``config/schema.yaml`` (:func:`pipeline.config.schema_default`, as a
dataclass field through :func:`~.defaults.schema_value`).

This package is the one place in the planner where a config's dicts are
read: each type has a reader of its section (``from_config``,
``from_section``), and :func:`as_verify_settings` and
:func:`as_kernel_settings` turn the flat dicts that callers not yet switched
to the typed settings still pass into the typed ones.

Its modules, by job (each imports only those listed before it):

``defaults``
    :func:`~.defaults.schema_value`, a field with the schema's default.
``trials``
    the perturbed trials (:class:`Perturbation`, :class:`VerifySettings`,
    their streams and ``TRUNCATE_SIGMA``) and the kernel's step
    (:class:`KernelSettings`).
``friction``
    friction text, labels and :class:`Friction`.
``pins``
    the global pin labels ``P1, P2, ...`` of the configured pin heights, or
    of heights fitted to the part (``fitted_pins``) when none are configured.
``claim``
    what "orients" means (:class:`ClaimSettings` and its checks).
``stages``
    speed limit, layout and design settings.
``planner``
    :class:`SearchSettings`, :class:`BandSettings` and :class:`PlannerSettings`.

Three frictions have three names: the planner's ``friction`` (a
:class:`Friction`, ``planner.mu_c``), the sweep's ``swept_frictions`` (the
grid of map frictions, ``sweep.mu_c``) and the per-trial ``trial_mu`` (the
array each verification trial draws).

This file holds no logic: it hands on the names of its modules.
"""
from __future__ import annotations

from pipeline.planning.core.settings.claim_rules import (RULES, ClaimSettings, check_confidence, check_required,
                                                   check_rule, check_tolerance)
from pipeline.planning.core.settings.defaults import schema_value
from pipeline.planning.core.settings.friction import Friction, friction_label, nominal_friction, parse_friction
from pipeline.planning.core.settings.pins import (BELOW_FENCE, FITTED_STEP, candidate_pins, fitted_pins,
                                                  pins_from_config)
from pipeline.planning.core.settings.planner import BandSettings, PlannerSettings, SearchSettings
from pipeline.planning.core.settings.stages import (DESIGN_KINDS, LAYOUT_MARGINS, DesignGrid, DesignLimits,
                                                    DesignSettings, LayoutSettings, SpeedPerturbation,
                                                    SpeedSettings)
from pipeline.planning.core.settings.trials import (HOLDOUT_STREAM, TRUNCATE_SIGMA, UNTRUNCATED_STREAM,
                                                    KernelSettings, Perturbation, VerifySettings,
                                                    as_kernel_settings, as_verify_settings)

__all__ = [
    "BELOW_FENCE", "DESIGN_KINDS", "FITTED_STEP", "HOLDOUT_STREAM", "LAYOUT_MARGINS", "RULES", "TRUNCATE_SIGMA",
    "UNTRUNCATED_STREAM", "BandSettings", "ClaimSettings", "DesignGrid", "DesignLimits", "DesignSettings",
    "Friction", "KernelSettings", "LayoutSettings", "Perturbation", "PlannerSettings", "SearchSettings",
    "SpeedPerturbation", "SpeedSettings", "VerifySettings", "as_kernel_settings", "as_verify_settings",
    "candidate_pins", "check_confidence", "check_required", "check_rule", "check_tolerance", "fitted_pins",
    "friction_label", "nominal_friction", "parse_friction", "pins_from_config", "schema_value",
]
