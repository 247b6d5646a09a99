"""Design for feeding: the smallest outline change that lets fixed pins orient a part.

``edits`` changes an outline (chamfers, notches, tabs: pure geometry, each
changed outline checked to be a simple polygon with positive area, within
the user's limits); ``search`` plans the changed parts with the planner of
``pinfeed plan``, smallest change first, and stops at the first that fixed
pins orient on held-out trials. It stands on the ``plans`` wing; the feeder
wing does not use it.
"""
