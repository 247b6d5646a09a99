"""Planning: which pins, in which order, orient a part - and how sure we are.

The package is five wings behind this front door; code outside planning
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

Wings import downwards only (core < claims < tight < family < plans; paper
uses the core alone). The package imports maps, parts, ``config`` and the
utilities; never sensing, present or workflow.
"""
from pipeline.planning.claims.orient import check_tolerance, describe_claim, min_trials, narrowest_arc
from pipeline.planning.claims.verify import DEFAULTS as VERIFY_DEFAULTS
from pipeline.planning.claims.verify import (PERTURB_DEFAULTS, corner_inputs, perturbed_batch,
                                             perturbed_inputs, predicted_sets, replay, verify_plan)
from pipeline.planning.core.arcs import arc_within, format_arcs, merge_arcs, merge_modulo
from pipeline.planning.core.settings import (BandSettings, ClaimSettings, Friction, Perturbation,
                                             PlannerSettings, SearchSettings, SpeedSettings, VerifySettings,
                                             candidate_pins, fitted_pins, friction_label, nominal_friction,
                                             parse_friction)
from pipeline.planning.core.types import PlanFile, as_plan_file, load_plan, validate_plan_file
from pipeline.planning.family.certificate import family_assumption, family_certificate_line
from pipeline.planning.family.members import check_family_mechanics
from pipeline.planning.paper.bands import extract_bands
from pipeline.planning.paper.planner import Planner, build_planner, load_maps, paper_depth
from pipeline.planning.plans.plan import (best_fixed_plan, mechanics_label, pick_tight_plan, plan_hint,
                                          plan_tight_all, planner_belt, tight_entry)
from pipeline.planning.plans.speed_limit import (DEFAULT_SPEEDS, attach_speed_limits,
                                                 perturbation_from_verify, speed_curve, speed_label,
                                                 stored_plan_speed, stored_speed_limit)
from pipeline.planning.plans.support_study import support_study
from pipeline.planning.tight.complete import margin_text

__all__ = [
    # core: arcs, plan file, settings
    "arc_within", "format_arcs", "merge_arcs", "merge_modulo",
    "PlanFile", "as_plan_file", "load_plan", "validate_plan_file",
    "PlannerSettings", "Friction", "SearchSettings", "ClaimSettings", "VerifySettings", "Perturbation",
    "SpeedSettings", "BandSettings",
    "candidate_pins", "fitted_pins", "friction_label", "nominal_friction", "parse_friction",
    # claims
    "VERIFY_DEFAULTS", "PERTURB_DEFAULTS", "corner_inputs", "perturbed_batch", "perturbed_inputs",
    "predicted_sets", "replay", "verify_plan",
    "check_tolerance", "describe_claim", "min_trials", "narrowest_arc",
    # tight
    "margin_text",
    # paper
    "extract_bands", "Planner", "build_planner", "load_maps", "paper_depth",
    # family
    "check_family_mechanics", "family_assumption", "family_certificate_line",
    # plans
    "best_fixed_plan", "mechanics_label", "pick_tight_plan", "plan_hint", "plan_tight_all",
    "planner_belt", "tight_entry",
    "DEFAULT_SPEEDS", "attach_speed_limits", "perturbation_from_verify", "speed_curve",
    "speed_label", "stored_plan_speed", "stored_speed_limit",
    "support_study",
]
