"""The planning core: what every wing shares.

``arcs`` (circular arcs of orientations), ``types`` (plans, verdicts and the
stored plan file with its JSON schema), ``settings`` (friction, candidate
pins and the planner's settings) and ``resting`` (a part's labelled resting
states). Imports parts, maps and the utilities; no other wing.
"""
