"""Figure geometry: band rectangles, labels, legends (artists inspected, not pixels)."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
import xarray as xr  # noqa: E402

from kernels.rollout import JAMMED, MISS, OK  # noqa: E402
from pipeline.present.figures.bands import MIN_THICKNESS, band_maps_figure, draw_map_panel  # noqa: E402

THETA = np.arange(360.0)


def _synthetic_map():
    """Band A: theta_f 100..106 from theta_i 0..119 and 103 from 260..299 (K_A two
    arcs); band B: theta_f exactly 300 from 200..259 (zero width); misses and jams."""
    tf = THETA.copy()
    st = np.full(360, MISS, dtype=np.int8)
    a1, b, a2, jam = slice(0, 120), slice(200, 260), slice(260, 300), slice(300, 330)
    tf[a1], st[a1] = 100 + 0.05 * THETA[a1], OK
    tf[b], st[b] = 300.0, OK
    tf[a2], st[a2] = 103.0, OK
    st[jam] = JAMMED
    return tf, np.zeros(360), st


def _rects(ax, prefix):
    out = {}
    for p in ax.patches:
        gid = p.get_gid() or ""
        if gid.startswith(prefix):
            out.setdefault(gid, set()).add(tuple(np.round([p.get_x(), p.get_y(), p.get_width(),
                                                           p.get_height()], 6)))
    return out


def test_band_rectangles_are_B_times_K():
    fig, ax = plt.subplots()
    tf, dy, st = _synthetic_map()
    bands = draw_map_panel(ax, THETA, tf, dy, st, threshold_T=5.0, factor_c=2.0)
    assert len(bands) == 2
    rects = _rects(ax, "band")
    # Each grid point stands for +-0.5 deg of theta_i; K_A's first arc starts at 0,
    # so its left half-step wraps to 359.5..360.
    k_a = [(359.5, 0.5), (-0.0, 119.5), (259.5, 40.0)]
    assert rects["band 0"] == {(x, 100.0, w, 5.95) for x, w in k_a}
    # Band B has zero width: drawn MIN_THICKNESS thick about 300.
    assert rects["band 1"] == {(199.5, 300 - MIN_THICKNESS / 2, 60.0, MIN_THICKNESS)}
    adjusted = _rects(ax, "adjusted")
    assert {r[0] for r in adjusted["adjusted 0"]} == {x for x, _ in k_a}
    for gid, rs in adjusted.items():
        for x, y, w, h in rs:
            assert h >= MIN_THICKNESS - 1e-9
    b = bands[0]
    (ys,) = {(r[1], r[3]) for r in adjusted["adjusted 0"]}
    assert ys == pytest.approx((b.adj_start, b.adj_width), abs=1e-6)
    # Distinguishable: the adjusted band is an unfilled hatched outline, the band filled.
    band_patch = next(p for p in ax.patches if p.get_gid() == "band 0")
    adj_patch = next(p for p in ax.patches if p.get_gid() == "adjusted 0")
    assert adj_patch.get_hatch() and adj_patch.get_facecolor()[3] == 0 and band_patch.get_facecolor()[3] > 0
    plt.close(fig)


def _text_artists(fig):
    return [t for t in fig.findobj(matplotlib.text.Text) if t.get_visible() and t.get_text()]


def test_band_map_figure_labels_legend_and_ticks():
    tf, dy, st = _synthetic_map()
    ds = xr.Dataset({"theta_f": (("d", "theta_i"), np.vstack([tf, tf])),
                     "dy": (("d", "theta_i"), np.vstack([dy, dy])),
                     "status": (("d", "theta_i"), np.vstack([st, st]))},
                    coords={"d": [-0.3, 0.3], "theta_i": THETA})
    fig = band_maps_figure({"minpower": ds, "tip": ds}, [-0.3, 0.3], 5.0, 2.0, r"test, $\mu_c$ = 0.2")
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels[:2] == [r"band $B_j \times K_j$", r"adjusted band $m_j \pm 2\sigma_j$"]
    assert "miss (no contact)" in labels and "jammed" in labels
    colours = {h.get_label(): h.get_color() for h in fig.legends[0].legend_handles[2:]}
    assert colours["miss (no contact)"] != colours["jammed"]
    for t in _text_artists(fig):  # underscores only inside mathtext
        outside = "".join(t.get_text().split("$")[::2])
        assert "_" not in outside, t.get_text()
    for ax in fig.axes:  # every panel row shows its tick labels
        fig.canvas.draw()
        assert all(lbl.get_visible() and lbl.get_text() for lbl in ax.get_xticklabels())
        assert ax.get_xlabel() == r"$\theta_i$ (deg)"
    from pipeline.present.figures import text_problems
    assert text_problems(fig) == []
    plt.close(fig)


@pytest.mark.parametrize("n_d, ncols, only_ok", [(4, 2, False), (18, 6, False), (1, 6, False), (2, 6, True)])
def test_map_figure_fits_its_labels(n_d, ncols, only_ok):
    """Also with one row of legend (every rollout ok: no miss or jam entries)."""
    from pipeline.present.figures import text_problems
    from pipeline.present.figures.maps import map_figure
    tf, dy, st = _synthetic_map()
    if only_ok:
        st = np.full_like(st, OK)
    ds = xr.Dataset({"theta_f": (("d", "theta_i"), np.tile(tf, (n_d, 1))),
                     "dy": (("d", "theta_i"), np.tile(dy, (n_d, 1))),
                     "status": (("d", "theta_i"), np.tile(st, (n_d, 1)))},
                    coords={"d": np.linspace(-0.9, 0.9, n_d), "theta_i": THETA},
                    attrs={"part_name": "asym_triangle", "model": "minpower", "mu_c": 0.15,
                           "pin_radius": 3.0, "length_unit": "mm"})
    fig = map_figure(ds, ncols, bands=(5.0, 2.0))
    assert text_problems(fig) == []
    assert len([ax for ax in fig.axes if ax.get_visible()]) == n_d
    plt.close(fig)


# ---------------------------------------------------------------- sequence diagrams

from pipeline.parts.part import Part  # noqa: E402
from pipeline.present.figures import text_problems  # noqa: E402
from pipeline.present.figures.sequence import sequence_figure  # noqa: E402


def _sequence(speeds=None):
    part = Part.from_vertices([[0, 0], [60, 0], [15, 35]], name="tri")
    pins = {"P1": 5.0, "P2": 22.5, "P3": 12.5, "P3v+2": 12.5}
    seq = ["P1", "P2", "P3v+2"] if speeds else ["P1", "P2", "P3"]
    states = part.stable_states()
    paths = {f"state {k}": [(th + 40 * j, y + 3 * j) for j in range(len(seq) + 1)]
             for k, (th, y) in enumerate(states, start=1)}
    plan = {"pins": seq, "final_sets": [{"start": 355.0, "width": 10.0}]}
    return sequence_figure(part, plan, pins, paths, 3.0, "tri: best plan", speeds=speeds), paths


@pytest.mark.parametrize("speeds", [None, {"P3v+2": 2.0}])
def test_sequence_labels_never_overlap_nor_clip(speeds):
    fig, paths = _sequence(speeds)
    assert text_problems(fig) == []
    texts = [t.get_text() for t in fig.findobj(matplotlib.text.Text)]
    # Every pin labelled with its height in every row; every pose with its orientation.
    assert texts.count("P2: 22.5 mm") == len(paths)
    if speeds:
        assert texts.count("P3v+2: 12.5 mm\n$v_{pin}$ = +2 $v_b$") == len(paths)
    assert sum(t.startswith(r"$\theta$ = ") for t in texts) == sum(len(p) for p in paths.values())
    assert "final orientation set(s): 355-5 deg" in fig._suptitle.get_text()
    plt.close(fig)


def test_text_problems_finds_an_overlap_and_a_clip():
    fig, ax = plt.subplots(figsize=(3, 2))
    ax.text(0.5, 0.5, "first label", transform=ax.transAxes)
    ax.text(0.52, 0.5, "second label", transform=ax.transAxes)
    fig.text(0.98, 0.5, "sticks out of the figure")
    problems = text_problems(fig)
    assert "overlap: 'first label' and 'second label'" in problems
    assert "clipped: 'sticks out of the figure'" in problems
    plt.close(fig)


def test_sensor_figures_labels_never_overlap_nor_clip(monkeypatch):
    from pipeline.present.figures import sensing as fs
    from pipeline.sensing.profiles import Profile, Sensor
    figs = []
    monkeypatch.setattr(fs, "save_figure", lambda fig, out, **kw: figs.append(fig))
    t = np.arange(0, 2, 1 / 200)
    rng = np.random.default_rng(0)
    sim = {f"state {k}": Profile(t, np.sin(k * t), np.cos(k * t)) for k in (1, 2, 3)}
    meas = {k: Profile(t, p.fx + 0.05 * rng.normal(size=t.size), p.fy) for k, p in sim.items()}
    fs.plot_profiles(sim, meas, Sensor(), "tri: force on the pin, sensor on P1 at y = 5 mm", "x.png")
    table = {"labels": list(sim), "elements": 40, "accuracy": 0.9, "wrong": 0.1, "trials": 30,
             "mean_scores": {s: {k: 30.0 if s == k else 20.0 for k in sim} for s in sim},
             "groups": [["state 1"], ["state 2", "state 3"]]}
    fs.plot_scores(table, "tri: sign-matrix scores", "y.png")
    for fig in figs:
        assert text_problems(fig) == []
        plt.close(fig)


# ---------------------------------------------------------------- verification


def test_verification_figure_counts_and_highlights_failures():
    from pipeline.present.figures.tables import verification_figure
    ok = {"kind": "fixed pins", "plan": ["P1", "P4"], "rows": [
        {"state": "state 1", "trials": 30, "successes": 30, "failures": 0, "reasons": {}}]}
    bad = {"kind": "with dynamic pins", "plan": ["P1", "P4v+2"], "rows": [
        {"state": "state 1", "trials": 30, "successes": 30, "failures": 0, "reasons": {}},
        {"state": "state 2", "trials": 30, "successes": 25, "failures": 5,
         "reasons": {"other band": 3, "jammed (wedged)": 2}}]}
    fig = verification_figure([ok, bad], "tri: verification")
    ax_ok, ax = fig.axes
    # Bar lengths per state: successes, then each reason, stacked to the trials.
    widths = {}
    for bar in ax.patches:
        widths.setdefault(round(bar.get_y() + bar.get_height() / 2), []).append(bar.get_width())
    assert sorted(widths[1]) == [0, 0, 30] and sorted(widths[0]) == [2, 3, 25]
    texts = {t.get_text(): t for t in ax.texts}
    assert texts["25/30"].get_color() == "tab:red" and texts["30/30"].get_color() == "black"
    assert ax.get_title() == "with dynamic pins: pins P1 → P4v+2: 5 of 60 trials failed"
    assert ax_ok.get_title().endswith("all 30 trials succeeded") and ax_ok.title.get_color() == "black"
    red = {lbl.get_text() for lbl in ax.get_yticklabels() if lbl.get_color() == "tab:red"}
    assert red == {"state 2"}
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert legend == ["success", "failure: jammed (wedged)", "failure: other band"]
    assert text_problems(fig) == []
    plt.close(fig)


def test_outline_figure_fences_touch_the_part():
    from pipeline.present.figures.outline import outline_figure
    part = Part.from_vertices([[0, 0], [60, 0], [60, 10], [10, 10], [10, 40], [0, 40]], name="bracket")
    fig = outline_figure(part, "cad/bracket.dxf")
    fences = {ln.get_gid(): np.transpose(ln.get_data()) for ln in fig.axes[0].lines if ln.get_gid()}
    assert len(fences) == len(part.stable_states()) == 3
    for k, (_, y_c) in enumerate(part.stable_states(), start=1):
        foot = fences[f"fence {k}"].mean(axis=0)
        n = foot / np.linalg.norm(foot)
        # The fence is y_c from the centroid and touches the outline without cutting it.
        assert np.linalg.norm(foot) == pytest.approx(y_c) and (part.vertices @ n).max() == pytest.approx(y_c)
    assert "6 vertices, non-convex" in fig.axes[0].get_title() and text_problems(fig) == []
    plt.close(fig)


def test_long_dynamic_sequence_labels_fit():
    part = Part.from_vertices([[0, 0], [60, 0], [60, 10], [10, 10], [10, 40], [0, 40]], name="bracket")
    pins = {"P1": -7.5, "P12": 22.5, "P13": 25.0, "P3v-2": -5.0, "P23v+1": 45.0}
    seq = list(pins)
    paths = {f"state {k}": [(th + 70 * j, y + 5 * j) for j in range(len(seq) + 1)]
             for k, (th, y) in enumerate(part.stable_states(), start=1)}
    plan = {"pins": seq, "final_sets": [{"start": 10.0, "width": 5.0}, {"start": 200.0, "width": 1.0}]}
    fig = sequence_figure(part, plan, pins, paths, 3.0, "bracket: best plan with dynamic pins",
                          speeds={"P3v-2": -2.0, "P23v+1": 1.0})
    assert text_problems(fig) == []
    plt.close(fig)
