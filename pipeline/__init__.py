"""pinfeed: design part feeders that orient flat parts with overhead pins.

Layers, lowest first (README "Layout"; ``tests/house/test_layers.py`` keeps them):
utilities (errors, logs, progress, provenance, checks), ``parts``, ``config``,
``maps``, ``planning``, ``sensing``, ``present``, ``workflow``, ``cli``.

Public API::

    from pipeline.maps import simulate
    from pipeline.parts.part import Part
    part = Part.from_vertices([(0, 0), (60, 0), (15, 35)], name="triangle")
    one = simulate.rollout(part, theta_i=30, d=0.3, mu_c=0.2, pin_radius=3)
    cube = simulate.compute_map(part, theta_i=range(0, 360), d=[-0.5, 0.5], mu_c=0.2, pin_radius=3)
"""
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("pinfeed")
except PackageNotFoundError:  # running from a source tree
    __version__ = "0+unknown"
