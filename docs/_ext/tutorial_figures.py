"""The tutorials' figures that the docs build draws (matplotlib's plot directive).

Each function returns a matplotlib figure drawn by pinfeed's own figure
functions from the current code, cheap enough for every build (a few seconds
each): a part's outline and resting states, a few rollouts against one pin, a
coarse map set with or without its bands, and, from a layout that the
own-part tutorial's commands write (stored beside the page as
``docs/tutorials/layout_wedge.json``; ``tests/docs/test_tutorial_commands.py``
checks that it still equals what those commands write), the plan's pin
sequence, the feeder drawing and a still of its animation. A page calls them
from a ``.. plot::`` block::

    from tutorial_figures import part_outline
    part_outline("bracket.dxf")

Every figure is checked for overlapping or clipped labels
(:func:`pipeline.present.figures.text_problems`); a problem fails the build.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

TUTORIALS = Path(__file__).resolve().parents[1] / "tutorials"
PIN_RADIUS = 3.0


def checked(fig, what: str):
    """``fig``, after making sure none of its labels overlap (``what`` names it
    in the error that fails the build otherwise)."""
    from pipeline.present.figures import text_problems
    problems = text_problems(fig)
    if problems:
        raise RuntimeError(f"{what} has overlapping labels: {problems}")
    return fig


def _checked(fig, what: str):
    return checked(fig, f"the tutorial figure {what}")


def tutorial_part(source: str):
    """A part by its source: a drawing in ``docs/tutorials/`` (``bracket.dxf``) or a
    part of the embedded default config (``asym_triangle``)."""
    if source.endswith((".dxf", ".svg")):
        from pipeline.parts.outlines import read_outline
        return read_outline(TUTORIALS / source).part(Path(source).stem)
    from pipeline.config import load_config
    from pipeline.workflow.commands import named_part
    return named_part(load_config(None), source)


def part_outline(source: str):
    """The part's outline (body frame), its centroid (+), the circle of radius a
    and the fence line of each resting state: ``pinfeed``'s outline figure."""
    from pipeline.present.figures.outline import outline_figure
    part = tutorial_part(source)
    return _checked(outline_figure(part, str(TUTORIALS / source) if "." in source else None),
                    f"outline of {source}")


def one_pin_turns(source: str, theta_i, d: float, mu_c: float):
    """How far the part turns against one pin, against the belt's travel since
    first contact, for each initial orientation (``pinfeed rollout --trajectory``)."""
    import matplotlib.pyplot as plt

    from pipeline.maps import simulate
    part = tutorial_part(source)
    fig, ax = plt.subplots(figsize=(6.4, 3.4))
    for theta in theta_i:
        one = simulate.rollout(part, theta_i=theta, d=d, mu_c=mu_c, pin_radius=PIN_RADIUS, trajectory=True)
        s = one["traj_s"].values
        turn = one["traj_theta"].values - one["traj_theta"].values[0]
        ax.plot(s[: turn.size], turn, marker=".", ms=3,
                label=fr"$\theta_i$ = {theta:g}°: $\theta_f$ = {float(one['theta_f']) % 360:.1f}°")
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.set_xlabel("belt travel since first contact (mm)", fontsize=8)
    ax.set_ylabel("turn since first contact (deg,\ncounter-clockwise positive)", fontsize=8)
    ax.set_title(f"{part.name} against one pin: $d$ = {d:+g}, $\\mu_c$ = {mu_c:g}, "
                 f"pin radius {PIN_RADIUS:g} mm (minpower)", fontsize=9)
    ax.tick_params(labelsize=7)
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    return _checked(fig, f"one pin of {source}")


def maps(source: str, d, theta_step: float, mu_c: float, bands=None, ncols: int = 6, mark=None):
    """The part's configuration maps (``pinfeed map`` then ``pinfeed plot-map``) on a
    grid of ``theta_step`` degrees of theta_i, one panel per d; ``bands``:
    ``(T, c)`` adds the bands (``--bands T,C``); ``mark``: theta_i values to ring
    on every panel (the rollouts a query returns)."""
    from pipeline.maps import simulate
    from pipeline.present.figures.maps import map_figure
    part = tutorial_part(source)
    ds = simulate.compute_map(part, np.arange(0.0, 360.0 - 1e-9, theta_step), [float(v) for v in d],
                              mu_c, PIN_RADIUS)
    ds.attrs.setdefault("part_name", part.name)
    fig = map_figure(ds, ncols=ncols, bands=bands)
    if mark is not None:
        for ax, value in zip(fig.axes, np.atleast_1d(ds["d"].values)):
            one = simulate.compute_map(part, [float(t) for t in mark], [float(value)], mu_c, PIN_RADIUS)
            ax.scatter(one["theta_i"].values, one["theta_f"].values.ravel(), s=70, facecolors="none",
                       edgecolors="tab:red", linewidths=1.2, zorder=5, label="queried")
            ax.legend(fontsize=7, loc="upper left")
    return _checked(fig, f"maps of {source}")


def stored_layout(name: str) -> dict:
    """The layout JSON that the own-part tutorial's commands write for ``name``,
    stored beside the page (``layout_NAME.json``)."""
    return json.loads((TUTORIALS / f"layout_{name}.json").read_text())


def _resting_states(part) -> dict:
    """label -> (theta deg, y_c mm) of the part's resting states, labelled as ``plan`` prints them."""
    return {f"state {k}": (float(t), float(y)) for k, (t, y) in enumerate(part.stable_states(), start=1)}


def layout_sequence(source: str):
    """The stored layout's plan as the pin-sequence figure: one row per resting
    state, the part before the first pin and after each pin (nominal rollouts of
    the plan's model at its friction)."""
    from pipeline.maps import simulate
    from pipeline.planning import Friction
    from pipeline.present.figures.sequence import sequence_figure
    part = tutorial_part(source)
    layout = stored_layout(part.name)
    plan = layout["plan"]
    pins = dict(zip(plan["pins"], plan["pin_heights_mm"]))
    mu_c = Friction.parse(plan["friction"]).nominal
    paths = {label: simulate.nominal_path(part, theta, y, plan["pin_heights_mm"], mu_c, PIN_RADIUS)
             for label, (theta, y) in _resting_states(part).items()}
    title = f"{part.name}: recommended plan at $\\mu_c$ {mu_c:g}, nominal paths"
    return _checked(sequence_figure(part, plan, pins, paths, PIN_RADIUS, title), f"sequence of {source}")


def layout_drawing(source: str):
    """The stored layout's feeder drawing (``pinfeed layout --out feeder.png``)."""
    from pipeline.present.figures.feeder import feeder_figure
    return _checked(feeder_figure(stored_layout(tutorial_part(source).name)), f"feeder of {source}")


def layout_frame(source: str, at: float = 0.55):
    """A still of the stored layout's animation (``pinfeed animate --layout``),
    at ``at`` of the belt travel it shows: parts before, at and after the pins."""
    from pipeline.planning import station_scene
    from pipeline.present.animate import station_figure, station_title
    part = tutorial_part(source)
    layout = stored_layout(part.name)
    scene = station_scene(part, layout, _resting_states(part), layout["mu_c"])
    still = station_figure(scene, station_title(part.name, scene, "the laid-out feeder"))
    still["draw"](at * scene.b_end)
    return _checked(still["fig"], f"animation still of {source}")
