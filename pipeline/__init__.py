"""pinfeed: design part feeders that orient flat parts with overhead pins.

Public API::

    from pipeline.parts import Part
    from pipeline import simulate
    part = Part.from_vertices([(0, 0), (60, 0), (15, 35)], name="triangle")
    one = simulate.rollout(part, theta_i=30, d=0.3, mu_c=0.2, pin_radius=3)
    cube = simulate.map(part, theta_i=range(0, 360), d=[-0.5, 0.5], mu_c=0.2, pin_radius=3)
"""
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("pinfeed")
except PackageNotFoundError:  # running from a source tree
    __version__ = "0+unknown"
