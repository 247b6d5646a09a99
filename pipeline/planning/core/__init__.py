"""The planning core: what every wing shares.

``arcs`` (circular arcs of orientations), ``types`` (plans, verdicts and the
stored plan file with its JSON schema), ``settings`` (friction, candidate
pins and the planner's settings), ``resting`` (a part's labelled resting
states) and ``nearest_axes`` (what a part's and a family's nearest "yes"
share: the tolerance ladder, a bisection, the axis records and their
lines). Imports parts, maps and the utilities; no other wing.
"""
