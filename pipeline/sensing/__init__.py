"""Sensing: force/torque profiles, sign matrices and classification
(``profiles``) and the sensor plan chosen among the stored tight plans
(``sensor_plan``). Above planning (it reads plans and verifies by the same
perturbed rollouts), below presentation.
"""
