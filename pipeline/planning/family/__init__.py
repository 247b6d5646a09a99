"""Plans that must hold for a family of supports (how the part presses on the belt).

``members`` (the family a config or command asks for), ``member_spaces``
(the family's parameter space), ``member_search`` (searching it for the
member farthest outside a plan's set), ``worst_member`` (whether that member
breaks a plan: the check and the complete search's checker), ``certificate``
(the family claim: epsilon and beta of the sampled members), ``shape``
(shape-tolerance families) and ``nearest`` (the nearest "yes" when no plan
holds). Imports the core, claims and tight wings.
"""
