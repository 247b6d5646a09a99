"""The paper's planner: adjusted bands of stored maps.

``bands`` (the bands of one configuration map) and ``planner`` (the breadth-
first planner over adjusted bands, as in "Orienting with Overhead Pins").
Imports the core wing only.
"""
