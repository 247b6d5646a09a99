"""A support family ready to plan with (spec section 9.4).

:func:`planning_family` checks that the planner's mechanics take point
supports and finds the family's extremes
(:mod:`pipeline.maps.support_spread`) on a coarse map grid at the planner's
friction: the members the search's nominal paths follow and under which the
verification replays the corners of its perturbation box.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.maps.support_spread import family_spread
from pipeline.parts.part import Part
from pipeline.parts.support_family import SupportFamily, parse_support_family
from pipeline.planning.core.settings import PlannerSettings, SearchSettings

EXTREMES_THETA_STEP = 3.0  # deg: the coarse grid the planner's extremes are found on


def check_family_mechanics(search: SearchSettings) -> None:
    """Refuse (one line) a family with mechanics that assume uniform pressure."""
    if search.model != "minpower" or search.belt_speed is not None:
        raise PinfeedError(f"a support family needs the quasi-static minpower model (the planner has "
                           f"model {search.model!r}, belt speed {search.belt_speed}); the other "
                           f"models assume uniform pressure: use model minpower without a belt speed")


def as_family(part: Part, family) -> SupportFamily:
    """``family`` as a :class:`SupportFamily` of ``part`` (parsing its text)."""
    return family if isinstance(family, SupportFamily) else parse_support_family(family, part)


def planning_family(part: Part, family, settings: PlannerSettings) -> SupportFamily | None:
    """The family (text or :class:`SupportFamily`) with its extremes found on
    the sweep's ``d`` and every ``EXTREMES_THETA_STEP`` degrees of theta_i at
    the nominal value of ``settings.friction``; ``None`` for uniform pressure
    alone."""
    family = as_family(part, family)
    if family.is_uniform:
        return None
    check_family_mechanics(settings.search)
    if family.extremes or len(family) == 1:
        return family if family.extremes else dataclasses.replace(family, extremes=(0,))
    spread = family_spread(part, family, np.arange(0.0, 360.0, EXTREMES_THETA_STEP),
                           list(settings.swept_d), settings.friction.nominal, settings.search.pin_radius)
    return dataclasses.replace(family, extremes=spread.extremes)
