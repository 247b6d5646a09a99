"""The tight planner: state sets pushed through pins, and the complete search.

``propagate`` (a set of states through one pin, on an outcome lattice),
``store`` (the lattice's outcomes kept in the catalog), ``search`` (the
transitions of state sets through pins, and the carried sets of one given
pin sequence), ``enumerate`` (every sequence on the pin grid, for the
complete search's evidence), ``complete`` (the complete fixed-pin search,
level by level), ``screen`` (one level of it screened, judged and
certified), ``records`` (its plans, its answer and their ranking), ``judge``
(candidate sequences replayed and judged on the verification's trials, and
certified on held-out ones) and ``certify`` (the carried sets of a chosen
plan). Imports the core and claims wings.
"""
