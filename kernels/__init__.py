"""Numba kernels of pinfeed: plain float64 arrays in and out, no I/O.

Public Python wrappers that validate input and pack results live in
``pipeline.simulate``; call those unless you need raw arrays.
"""
