"""Planning: circular arcs (``arcs``), bands of a map (``bands``), the paper's
adjusted-band planner (``paper``), the tight planner (state sets through one
pin in ``propagate``, search in ``search``, its refinement shards in
``lattice_store``, and ``plan``: planning a part at a friction, picking a
stored plan), verification by perturbed full rollouts (``verify``) and the
speed limit of a plan (``speed_limit``).

Imports maps, parts, ``config`` and the utilities; never sensing, present or
workflow.
"""
