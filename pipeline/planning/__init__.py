"""Planning: which pins, in which order, orient a part - and how sure we are.

The package is eight wings behind this front door; code outside planning
imports only the names in :data:`__all__` from here (``tests/house`` checks
it), so a wing can change inside without touching its callers.

``core``
    arcs of orientations, plan types and the plan file, the planner's
    settings (friction, pins), resting states.
``claims``
    verification by perturbed full rollouts, the orientation verdict and its
    confidence bounds.
``tight``
    state sets through pins, their stored outcomes, the branch-and-bound and
    the complete fixed-pin search, carried sets.
``paper``
    the paper's adjusted-band planner over stored maps.
``family``
    plans for a family of supports: worst member, family certificate.
``plans``
    the front of the planner: plan, verify and recommend a part at each
    friction; speed limits; support studies.
``design``
    design for feeding: the smallest chamfer, notch or tab that lets fixed
    pins orient a part that they do not (the planner of ``plans`` tries each
    changed outline, smallest change first).
``feeder``
    what a feeder's drawings need from the physics: trials past the pins on
    the belt's clock (lanes), the layout (stations, pitch, belt width,
    throughput) of a stored plan, the passages an animation draws, the
    set-up of one pin contact. ``pipeline.present`` draws these and replays
    nothing itself (``tests/house/test_present_draws.py``).

Each name is imported from its wing when it is first asked for (PEP 562),
so a caller that needs the arcs does not pay for the planner, its Numba
kernels and scipy; ``_WHERE`` says where each name lives.

Wings import downwards only (core < claims < tight < family < plans <
feeder, and design beside feeder, on plans; paper uses the core alone). The package imports maps, parts, ``config`` and the
utilities; never sensing, present or workflow.
"""
from __future__ import annotations

import importlib

# The front door's names, by the wing module that defines them ("NAME=DEFINED"
# where the door gives a name of its own).
_WHERE = {
    "core.arcs": "arc_within format_arcs merge_arcs merge_modulo",
    "core.settings": "BandSettings ClaimSettings DESIGN_KINDS DesignGrid DesignLimits DesignSettings Friction "
                     "KernelSettings LayoutSettings Perturbation PlannerSettings SearchSettings "
                     "SpeedPerturbation SpeedSettings VerifySettings candidate_pins fitted_pins friction_label "
                     "nominal_friction parse_friction",
    "core.claim": "Claim",
    "core.plan_records": "ABSENT Plan RestingState",
    "core.types": "PlanFile TightEntry as_plan_file load_plan validate_plan_file",
    "core.nearest_axes": "SUBJECT_FAMILY SUBJECT_PART nearest_yes_lines",
    "claims.orient": "check_tolerance describe_claim min_trials narrowest_arc",
    "claims.tails": "describe_untruncated truncation_text untruncated_check",
    "claims.trials": "VERIFY_DEFAULTS=DEFAULTS PERTURB_DEFAULTS corner_inputs perturbed_batch perturbed_inputs",
    "claims.replay": "replay replayed_paths",
    "claims.verify": "predicted_sets verify_plan",
    "tight.records": "margin_text",
    "paper.bands": "extract_bands",
    "paper.coarse": "COARSE_MU_C=MU_C COARSE_PIN_RADIUS=PIN_RADIUS best_coarse_plan coarse_plan_paths",
    "paper.planner": "Planner build_planner load_maps paper_depth",
    "family.certificate": "family_assumption family_certificate_line",
    "family.members": "check_family_mechanics",
    "family.shape": "attach_shape_tolerance shape_line",
    "plans.plan": "plan_tight_all",
    "plans.planner": "mechanics_label planner_belt",
    "plans.stored_plan": "best_fixed_plan pick_tight_plan plan_hint tight_entry",
    "plans.speed_limit": "DEFAULT_SPEEDS attach_speed_limits speed_curve speed_label stored_plan_speed "
                         "stored_speed_limit",
    "plans.support_study": "support_study",
    "design.edits": "ChangeRefused OutlineChange apply_change ccw_outline changed_area edge_lengths",
    "design.search": "design_part",
    "feeder.contact": "mechanics_scene",
    "feeder.lanes": "Lane Trial pin_height pin_reach run_trials trial_lanes",
    "feeder.layout": "layout_plan",
    "feeder.passages": "StationScene layout_inputs plan_inputs recommended_index roll_plan station_scene",
    "feeder.stored": "final_sets_warning layout_stored",
}
_MODULE_OF = {name.partition("=")[0]: (module, name.partition("=")[2] or name)
              for module, names in _WHERE.items() for name in names.split()}

__all__ = list(_MODULE_OF)


def __getattr__(name: str):
    """Import ``name`` from its wing on first use and keep it here."""
    try:
        module, attr = _MODULE_OF[name]
    except KeyError:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    value = getattr(importlib.import_module(f"{__name__}.{module}"), attr)
    globals()[name] = value
    return value


def __dir__():
    """The names defined here and those of the front door, imported or not."""
    return sorted(set(globals()) | set(__all__))
