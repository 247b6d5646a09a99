"""The paper's planner: adjusted bands of stored maps.

``bands`` (the bands of one configuration map), ``planner`` (the breadth-
first planner over adjusted bands, as in "Orienting with Overhead Pins") and
``coarse`` (the best plan on coarse maps and its nominal paths, for the
gallery). Imports the core wing only.
"""
