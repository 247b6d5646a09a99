"""A part's recommended plans: the planner as the command line and the workflow call it.

``plan`` (search, verify, rank and recommend at each friction; pick a stored
plan), ``speed_limit`` (how fast a plan may run) and ``support_study`` (a
plan's behaviour across a support family). The top wing: imports every other.
"""
