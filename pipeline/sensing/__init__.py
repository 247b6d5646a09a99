"""Sensing: force/torque profiles, sign matrices and classification
(``profiles``), the sensor plan chosen among the stored tight plans
(``sensor_plan``) and a measured profile classified against the stored
results (``measured``, behind ``pinfeed sense classify``). Above planning
(it reads plans and verifies by the same perturbed rollouts), below
presentation.
"""
