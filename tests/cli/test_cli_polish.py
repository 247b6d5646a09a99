"""Command-line output for people: arcs, progress, help text, trajectory table, hints."""
import io

import pytest

from pipeline.cli import build_parser, main
from pipeline.planning.paper.bands import format_arc, format_arcs
from pipeline.progress import progress


@pytest.mark.parametrize("start, width, text", [
    (223.14, 9.06, "223.1-232.2 deg"),
    (-5.0, 10.0, "355.0-5.0 deg"),       # through 0: both ends within [0, 360)
    (350.0, 10.0, "350.0-0.0 deg"),      # ends at 360: printed as 0
    (720.5, 0.0, "0.5 deg"),             # a single angle
    (10.0, 360.0, "any orientation (0-360 deg)"),
])
def test_format_arc(start, width, text):
    assert format_arc(start, width) == text


def test_format_arcs_takes_plan_dicts():
    assert format_arcs([{"start": 359.96, "width": 0.0}, (90, 5)]) == "0.0 deg, 90.0-95.0 deg"
    assert format_arcs([]) == "none"


def test_progress_lines_in_logs_bar_on_a_terminal():
    log = io.StringIO()
    assert list(progress(range(20), 20, "sweep", unit="shard", stream=log)) == list(range(20))
    lines = log.getvalue().splitlines()
    assert lines[0] == "sweep: 20 shards to do"
    assert [ln.split()[1] for ln in lines[1:]] == [f"{k}/20" for k in range(2, 21, 2)]
    assert "\r" not in log.getvalue()

    class Tty(io.StringIO):
        def isatty(self):
            return True
    tty = Tty()
    assert list(progress(range(5), 5, "verify", stream=tty)) == list(range(5))
    assert "\r" in tty.getvalue() and "5/5" in tty.getvalue()
    quiet = io.StringIO()
    list(progress(range(5), 5, "x", stream=quiet, enabled=False))
    assert quiet.getvalue() == ""


def _all_help(parser):
    yield parser.format_help()
    for action in parser._actions:
        if isinstance(action.choices, dict):  # a subcommand table
            for sub in action.choices.values():
                yield from _all_help(sub)


def test_help_has_no_restructuredtext_markup():
    texts = list(_all_help(build_parser()))
    assert len(texts) > 10
    for text in texts:
        assert "``" not in text and ":func:" not in text


def test_rollout_trajectory_table(capsys):
    assert main(["rollout", "--vertices", "0,0 60,0 15,35", "--mu-c", "0.2", "--pin-radius", "3",
                 "--theta-i", "30", "--d", "0.3", "--trajectory"]) == 0
    out = capsys.readouterr().out
    assert "[[" not in out and "trajectory of theta_i = 30 deg" in out
    table = out.split("theta (deg)")[1].strip().splitlines()
    # The same rollout through the Python API: the table shows 11 evenly spaced
    # samples of its trajectory (all of them if fewer), both ends included.
    import numpy as np

    from pipeline.maps import simulate
    from pipeline.parts.part import Part
    ds = simulate.rollout(Part.from_vertices([[0, 0], [60, 0], [15, 35]]), 30.0, 0.3, 0.2, 3.0,
                          trajectory=True)
    n = ds.traj_s.size
    assert f"({n} samples;" in out and len(table) == min(11, n)
    first = [float(v) for v in table[0].split()]
    assert first[:3] == [0.0, 0.0, 0.0] and first[3] == pytest.approx(30.0)
    last = [float(v) for v in table[-1].split()]
    assert last[0] == pytest.approx(float(ds.traj_s[-1]), abs=0.006)
    assert abs((last[3] - float(ds.theta_f) + 180.0) % 360.0 - 180.0) <= 0.006
    assert np.all(np.diff([float(r.split()[0]) for r in table]) > 0)  # s grows down the table


def test_sense_hint_names_pinfeed_plan_for_an_ad_hoc_part(tmp_path):
    from pipeline.planning.plans.stored_plan import plan_hint
    planned = ["asym_triangle"]
    assert "make run" in plan_hint(planned, "asym_triangle", tmp_path)
    hint = plan_hint(planned, "bracket", tmp_path)
    assert hint == f"run 'pinfeed plan --part bracket --out {tmp_path / 'plans' / 'bracket.json'}'"


def test_plot_map_bands_option(tmp_path, capsys):
    import numpy as np

    from pipeline.maps import simulate
    from pipeline.maps.io import write_atomic
    from pipeline.parts.part import Part
    part = Part.from_vertices([[0, 0], [60, 0], [15, 35]], name="tri")
    write_atomic(simulate.compute_map(part, np.arange(0, 360, 30.0), [0.3], 0.2, 3.0), tmp_path / "m.h5")
    assert main(["plot-map", str(tmp_path / "m.h5"), "--out", str(tmp_path / "m.png"),
                 "--bands", "5,2"]) == 0
    assert (tmp_path / "m.png").is_file()
    assert main(["plot-map", str(tmp_path / "m.h5"), "--out", str(tmp_path / "m.png"),
                 "--bands", "5"]) == 2
    assert "--bands '5': give the band threshold T" in capsys.readouterr().err
