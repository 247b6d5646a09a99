"""Claims about a plan, from perturbed full rollouts.

``trials`` (the trials a plan is replayed on: the perturbation box, its
corners, the held-out trials' settings), ``replay`` (those trials rolled
through the whole pin sequence; the replays the carried-sets figure draws),
``verify`` (a stored plan's trials replayed and judged against the sets it
predicts), ``tails`` (the recommended plan replayed once more with its
normals not cut at 2 sigma), ``orient`` (judging a verification: does the
plan orient the part within the tolerance, and how it is said) and
``confidence`` (bounds on a share and a width from a finite number of
trials). Imports the core wing only.
"""
