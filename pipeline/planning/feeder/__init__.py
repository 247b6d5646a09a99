"""A feeder to build: what the layout and the animations need from the physics.

``lanes`` (perturbed or nominal trials rolled past the pins with their
trajectories, placed on the belt's clock; where a pin first touches an
outline), ``layout`` (pin stations, pitch, belt width and throughput of one
plan of fixed pins), ``stored`` (the layout of a stored plan: its speed limit
and belt speed), ``passages`` (the passages an animation draws: every state
past a plan's pins, or a laid-out feeder's stream of parts; the plan an
animation shows) and ``contact`` (the set-up of one pin contact for the
mechanics diagram). ``pipeline.present`` only draws what these compute.
The top wing: imports every other (``plans`` for the speed limit); none
imports it.
"""
