"""Plans that must hold for a family of supports (how the part presses on the belt).

``members`` (the family a config or command asks for), ``worst_member``
(searching the family for a member a plan fails) and ``certificate`` (the
family claim: epsilon and beta of the sampled members). Imports the core,
claims and tight wings.
"""
