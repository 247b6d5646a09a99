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

Wings import downwards only (core < claims < tight < family < plans <
feeder, and design beside feeder, on plans; paper uses the core alone). The package imports maps, parts, ``config`` and the
utilities; never sensing, present or workflow.
"""
from pipeline.planning.claims.tails import describe_untruncated, truncation_text, untruncated_check
from pipeline.planning.claims.orient import check_tolerance, describe_claim, min_trials, narrowest_arc
from pipeline.planning.claims.verify import DEFAULTS as VERIFY_DEFAULTS
from pipeline.planning.claims.verify import (PERTURB_DEFAULTS, corner_inputs, perturbed_batch,
                                             perturbed_inputs, predicted_sets, replay, replayed_paths,
                                             verify_plan)
from pipeline.planning.core.arcs import arc_within, format_arcs, merge_arcs, merge_modulo
from pipeline.planning.core.settings import (BandSettings, ClaimSettings, Friction, Perturbation,
                                             PlannerSettings, SearchSettings, SpeedSettings, VerifySettings,
                                             candidate_pins, fitted_pins, friction_label, nominal_friction,
                                             parse_friction)
from pipeline.planning.core.types import PlanFile, as_plan_file, load_plan, validate_plan_file
from pipeline.planning.design.edits import (KINDS as DESIGN_KINDS, ChangeRefused, DesignGrid, OutlineChange,
                                            apply_change, ccw_outline, changed_area, edge_lengths)
from pipeline.planning.design.search import DesignLimits, DesignSettings, design_part
from pipeline.planning.family.certificate import family_assumption, family_certificate_line
from pipeline.planning.family.members import check_family_mechanics
from pipeline.planning.family.nearest import nearest_yes_lines
from pipeline.planning.family.shape import attach_shape_tolerance, shape_line
from pipeline.planning.feeder.contact import mechanics_scene
from pipeline.planning.feeder.lanes import Lane, Trial, pin_height, pin_reach, run_trials, trial_lanes
from pipeline.planning.feeder.layout import LAYOUT_DEFAULTS, check_layout_settings, layout_plan
from pipeline.planning.feeder.passages import (StationScene, layout_inputs, plan_inputs, recommended_index,
                                               roll_plan, station_scene)
from pipeline.planning.feeder.stored import final_sets_warning, layout_stored
from pipeline.planning.paper.bands import extract_bands
from pipeline.planning.paper.coarse import MU_C as COARSE_MU_C
from pipeline.planning.paper.coarse import PIN_RADIUS as COARSE_PIN_RADIUS
from pipeline.planning.paper.coarse import best_coarse_plan, coarse_plan_paths
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
    "predicted_sets", "replay", "replayed_paths", "verify_plan",
    "check_tolerance", "describe_claim", "min_trials", "narrowest_arc",
    "describe_untruncated", "truncation_text", "untruncated_check",
    # tight
    "margin_text",
    # paper
    "extract_bands", "Planner", "build_planner", "load_maps", "paper_depth",
    "COARSE_MU_C", "COARSE_PIN_RADIUS", "best_coarse_plan", "coarse_plan_paths",
    # family
    "check_family_mechanics", "family_assumption", "family_certificate_line", "nearest_yes_lines", "attach_shape_tolerance", "shape_line",
    # plans
    "best_fixed_plan", "mechanics_label", "pick_tight_plan", "plan_hint", "plan_tight_all",
    "planner_belt", "tight_entry",
    "DEFAULT_SPEEDS", "attach_speed_limits", "perturbation_from_verify", "speed_curve",
    "speed_label", "stored_plan_speed", "stored_speed_limit",
    "support_study",
    # design
    "DESIGN_KINDS", "ChangeRefused", "DesignGrid", "DesignLimits", "DesignSettings", "OutlineChange",
    "apply_change", "ccw_outline", "changed_area", "design_part", "edge_lengths",
    # feeder
    "Lane", "Trial", "pin_height", "pin_reach", "run_trials", "trial_lanes",
    "LAYOUT_DEFAULTS", "check_layout_settings", "layout_plan", "final_sets_warning", "layout_stored",
    "StationScene", "layout_inputs", "plan_inputs", "recommended_index", "roll_plan", "station_scene",
    "mechanics_scene",
]
