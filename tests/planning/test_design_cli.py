"""``pinfeed design`` on the command line: exit codes, one-line errors, the no-change message."""
from __future__ import annotations

import json

import pytest

from cli_runs import run_cli, small_config_file

TRAPEZOID = "0,0 70,0 50,25 10,25"


@pytest.mark.parametrize("options,message", [
    (["--keep-edges", "9"], "--keep-edges 9: the outline has edges 0 to 3"),
    (["--keep-edges", "a"], "--keep-edges 'a'"),
    (["--max-change", "2"], "--max-change must be a fraction in (0, 1]"),
    (["--notch", "0.1"], "--notch '0.1': give sizes as 'WIDTH:DEPTH,...'"),
    (["--chamfer", "0,0.1"], "--chamfer: sizes are fractions of a and must be > 0"),
    (["--kinds", "hole"], "--kinds hole: choose from chamfer,notch,tab"),
    (["--positions", "1.5"], "--positions '1.5'"),
    (["--min-wall", "-1"], "--min-wall must be a length >= 0 mm"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path, options, message):
    code, out, err = run_cli(capsys, ["design", "--vertices", TRAPEZOID, "--out", str(tmp_path), *options])
    lines = [line for line in err.splitlines() if line.startswith("pinfeed: error:")]
    assert code == 2 and len(lines) == 1 and message in lines[0], err
    assert not list(tmp_path.iterdir())


def test_no_part_is_an_error(capsys):
    code, _, err = run_cli(capsys, ["design"])
    assert code == 2 and "give --part NAME" in err


def test_no_change_within_the_limits_says_so_and_exits_0(capsys, tmp_path):
    config = small_config_file(tmp_path)
    code, out, err = run_cli(capsys, ["design", "--vertices", TRAPEZOID, "--name", "trap", "--config", str(config),
                                      "--catalog", str(tmp_path / "catalog"), "--depth", "1", "--mu-c", "0.2",
                                      "--kinds", "chamfer", "--max-change", "0.0001", "--out", str(tmp_path / "d")])
    assert code == 0, err
    assert "trap: no change within the limits makes a fixed-pin plan of up to 1 pins" in out
    assert "tried 0 changes; 16 refused by the limits" in out
    stored = json.loads((tmp_path / "d" / "trap.json").read_text())
    assert stored["outcome"] == "no change helps" and stored["config_hash"] and stored["git_commit"]
    assert (tmp_path / "d" / "trap.dxf").is_file() and (tmp_path / "d" / "trap.png").is_file()
    assert "edge 3: (10, 25) to (0, 0) mm" in err


def test_the_same_inputs_give_the_same_files(capsys, tmp_path):
    """Two runs write the same JSON apart from its time stamp, the same figure,
    and the same DXF apart from its time stamps and per-save version GUID."""
    config = small_config_file(tmp_path)
    outputs = []
    for run in ("a", "b"):
        code, _, err = run_cli(capsys, ["design", "--vertices", TRAPEZOID, "--name", "trap", "--config", str(config),
                                        "--catalog", str(tmp_path / "catalog"), "--depth", "1", "--mu-c", "0.2",
                                        "--kinds", "chamfer", "--chamfer", "0.1", "--max-change", "0.001",
                                        "--out", str(tmp_path / run)])
        assert code == 0, err
        stored = json.loads((tmp_path / run / "trap.json").read_text())
        stored.pop("created")
        stored.pop("files")
        dxf = (tmp_path / run / "trap.dxf").read_text().splitlines()
        outputs.append((stored, (tmp_path / run / "trap.png").read_bytes(), dxf))
    (json_a, png_a, dxf_a), (json_b, png_b, dxf_b) = outputs
    assert json_a == json_b and png_a == png_b
    differ = [k for k, (x, y) in enumerate(zip(dxf_a, dxf_b)) if x != y]
    stamps = ("$TDCREATE", "$TDUCREATE", "$TDUPDATE", "$TDUUPDATE", "$VERSIONGUID")
    assert all(any(s in dxf_a[k - 2] for s in stamps) or " @ " in dxf_a[k] for k in differ), \
        [dxf_a[k - 2:k + 1] for k in differ]


def test_the_workflow_rule_skips_a_part_whose_plan_orients(tmp_path):
    from pipeline.config import load_config
    from pipeline.workflow.design import design_rule
    config = load_config()
    plan = tmp_path / "asym_triangle.json"
    plan.write_text(json.dumps({"tight": [{"orients": True, "recommended": {"pins": ["P14", "P6"]}}]}))
    out = tmp_path / "designs" / "asym_triangle.json"
    result = design_rule(config, "asym_triangle", plan, out)
    assert result["outcome"] == "already orients" and result["tried"] == []
    assert json.loads(out.read_text())["original"]["pins"] == ["P14", "P6"]
    assert out.with_suffix(".dxf").is_file() and out.with_suffix(".png").is_file()
