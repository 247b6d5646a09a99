"""The planning core: what every wing shares.

``arcs`` (circular arcs of orientations), ``types`` (the stored plan file's
records with its JSON schema), ``plan_records`` (one plan's records: arcs,
states, steps, verification), ``settings`` (a package: friction, candidate
pins and the planner's settings), ``resting`` (a part's labelled resting
states) and ``nearest_axes`` (what a part's and a family's nearest "yes"
share: the tolerance ladder, a bisection, the axis records and their
lines). Imports parts, maps and the utilities; no other wing.
"""
