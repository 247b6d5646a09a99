"""A parts library through the workflow: a folder of drawings expands into one
job per part (a sheet of two parts gives two), an unreadable drawing and a
refused part are listed with their reasons while the other parts are planned,
the page, CSV and JSON agree and count the classes right, every link of the
page resolves, a re-run does nothing and a drawing added later adds only its
own jobs, the library rules pass ``snakemake --lint``, and a part whose
planning fails is recorded, not raised."""
from __future__ import annotations

import csv
import json
import re
import shutil
from pathlib import Path

import pytest
import yaml

from workflow_runs import ROOT, run_snakemake

from pipeline.errors import PinfeedError
from pipeline.workflow.library import drawing_ids, library_files, library_plan

DRAWINGS = ROOT / "examples" / "library" / "drawings"
# Small and quick: a triangle, a sheet of two parts, a sheet with one part refused, an open outline.
USED = ("triangle_right_50x30.dxf", "svg_two_parts.svg", "sheet_one_refused.dxf", "broken_open_outline.dxf")


def tiny_config(root: Path) -> Path:
    """A library config of the drawings in ``root/drawings`` with small planner settings."""
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    cfg.update(name="lib", catalog_dir=str(root / "catalog"))
    pc = cfg["planner"]
    pc.update(depth=1, mu_c=0.15, frictions=[], parts=[])
    pc["dynamic"].update(depth=0, speeds=[])
    cfg["verify"].update(trials=10, rule="point")
    cfg["speed"].update(trials=4, speeds=[50, 200])
    cfg["layout"] = {"trials": 4, "speed_trials": 4}
    cfg["library"] = {"paths": ["drawings"], "time_limit_s": 10}
    path = root / "lib.yaml"
    path.write_text(yaml.safe_dump(cfg))
    return path


@pytest.fixture(scope="module")
def library_run(tmp_path_factory):
    root = tmp_path_factory.mktemp("library")
    (root / "drawings").mkdir()
    for name in USED:
        shutil.copy(DRAWINGS / name, root / "drawings" / name)
    config = tiny_config(root)
    run = run_snakemake(root, "--configfile", str(config), "--keep-going", "library")
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    return root, config


def test_paths_expand_into_drawings_and_a_sheet_into_parts(tmp_path):
    for name in ("triangle_right_50x30.dxf", "svg_two_parts.svg", "broken_open_outline.dxf"):
        shutil.copy(DRAWINGS / name, tmp_path / name)
    (tmp_path / "notes.txt").write_text("not a drawing")
    assert [f.name for f in library_files([str(tmp_path)])] == sorted(
        ["triangle_right_50x30.dxf", "svg_two_parts.svg", "broken_open_outline.dxf"])
    assert [f.name for f in library_files([str(tmp_path / "*.svg"), str(tmp_path / "svg_two_parts.svg")])] == [
        "svg_two_parts.svg"]  # a glob and a file naming one drawing: listed once
    plan = library_plan({"library": {"paths": [str(tmp_path)]}}, cache=tmp_path / "cache")
    assert plan["parts"] == {
        "svg_two_parts.svg-0": {"drawing": "svg_two_parts.svg", "label": "svg_two_parts.svg#0", "name": "svg_two_parts_0"},
        "svg_two_parts.svg-1": {"drawing": "svg_two_parts.svg", "label": "svg_two_parts.svg#1", "name": "svg_two_parts_1"},
        "triangle_right_50x30.dxf-0": {"drawing": "triangle_right_50x30.dxf", "label": "triangle_right_50x30.dxf#0",
                                       "name": "triangle_right_50x30_0"}}
    assert "broken_open_outline.dxf" in plan["drawings"]  # read (and refused) by its own job
    assert len(list((tmp_path / "cache").glob("*.json"))) == 3  # cached by content for the next load
    with pytest.raises(PinfeedError, match="library/paths.*no .dxf or .svg"):
        library_files([str(tmp_path / "*.step")])


def test_same_file_names_in_two_folders_get_distinct_ids(tmp_path):
    for sub in ("a", "b"):
        (tmp_path / sub).mkdir()
        shutil.copy(DRAWINGS / "tab_10x6.dxf", tmp_path / sub / "tab.dxf")
    ids = drawing_ids(library_files([str(tmp_path / "*" / "*.dxf")]))
    assert sorted(ids) == ["a__tab.dxf", "b__tab.dxf"]


def rows_of(root):
    return json.loads((root / "results" / "lib" / "library.json").read_text())


def test_every_part_has_a_row_and_refusals_say_why(library_run):
    root, _ = library_run
    doc = rows_of(root)
    by_label = {r["label"]: r for r in doc["rows"]}
    assert sorted(by_label) == ["broken_open_outline.dxf", "sheet_one_refused.dxf#0", "sheet_one_refused.dxf#1",
                                "sheet_one_refused.dxf#2", "svg_two_parts.svg#0", "svg_two_parts.svg#1",
                                "triangle_right_50x30.dxf#0"]
    broken = by_label["broken_open_outline.dxf"]
    assert broken["class"] == "not readable" and "open outline" in broken["reason"]
    assert "cross each other or touch" in by_label["sheet_one_refused.dxf#0"]["reason"]
    planned = [r for r in doc["rows"] if r["class"] != "not readable"]
    assert len(planned) == 4  # the other parts went on, the refused sheet's good part among them
    for r in planned:
        assert r["plan_file"] and r["thumbnail"] and r["resting_states"] >= 3
        assert r["answer"] and r["width_mm"] > 0
        assert (r["width_deg"] is not None) == (r["class"] in ("fixed pins", "moving pins"))
        plan = json.loads((root / "results" / "lib" / r["plan_file"]).read_text())
        assert plan["tight"][0]["time_limit_s"] == 10  # library.time_limit_s reached the planner
        assert len(plan["tight"][0]["initial_states"]) == r["resting_states"]
    thumb = (root / "results" / "lib" / by_label["svg_two_parts.svg#0"]["thumbnail"]).read_text()
    assert "<svg" in thumb and thumb.count("<path") >= 1  # the part drawn, no axes


def test_page_csv_and_json_agree_and_the_summary_counts_right(library_run):
    root, _ = library_run
    results = root / "results" / "lib"
    doc = rows_of(root)
    with open(results / "library.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    assert [r["label"] for r in table] == [r["label"] for r in doc["rows"]]
    for got, want in zip(table, doc["rows"]):
        assert got["class"] == want["class"] and got["answer"] == want["answer"]
        assert got["plan_file"] == (want["plan_file"] or "")
    counts = {}
    for r in doc["rows"]:
        counts[r["class"]] = counts.get(r["class"], 0) + 1
    assert doc["counts"] == counts and sum(counts.values()) == 7
    assert doc["summary"].startswith("7 parts: ") and f"{counts['not readable']} not readable" in doc["summary"]
    page = (results / "library.html").read_text()
    assert doc["summary"] in page.replace("&quot;", '"')
    assert page.count('<tr data-class=') == 7
    for r in doc["rows"]:
        assert f'data-class="{r["class"]}" id="{r["key"]}"' in page
    assert "http" not in re.sub(r'xmlns[^"]*"[^"]*"', "", page)  # nothing fetched from elsewhere


def test_every_link_and_image_of_the_page_resolves(library_run):
    root, _ = library_run
    results = root / "results" / "lib"
    page = (results / "library.html").read_text()
    targets = re.findall(r'(?:href|src)="([^"#]+)"', page)
    assert any(t.endswith("plan.json") for t in targets) and any(t.endswith("part.svg") for t in targets)
    assert any(t.endswith("layout.svg") for t in targets) or "orients with" not in page
    missing = [t for t in targets if not (results / t).is_file()]
    assert not missing


def test_rerun_does_nothing_and_a_new_drawing_adds_only_its_jobs(library_run):
    root, config = library_run
    again = run_snakemake(root, "--configfile", str(config), "-n", "library")
    assert again.returncode == 0 and "Nothing to be done" in again.stdout + again.stderr
    added = root / "drawings" / "tab_10x6.dxf"
    shutil.copy(DRAWINGS / "tab_10x6.dxf", added)
    try:
        dry = run_snakemake(root, "--configfile", str(config), "-n", "library")
        assert dry.returncode == 0, dry.stderr[-2000:]
        jobs = re.findall(r"^rule (\w+):\n(?:    .*\n)*?    wildcards: (.*)$", dry.stdout, flags=re.M)
        assert sorted(jobs) == [("library_part", "key=tab_10x6.dxf-0"), ("library_read", "drawing=tab_10x6.dxf")]
        assert re.search(r"^rule library:$", dry.stdout, flags=re.M)  # and the page, which lists every part
    finally:
        added.unlink()


def test_the_library_rules_pass_snakemake_lint(library_run):
    root, config = library_run
    lint = run_snakemake(root, "--configfile", str(config), "--lint")
    text = lint.stdout + lint.stderr
    assert "library" not in "".join(re.findall(r"^Lints for .*$|^    \* .*$", text, flags=re.M)), text[-3000:]
    assert "Congratulations" in text or "Lints for" in text, text[-3000:]  # the lint ran


def test_a_part_whose_planning_fails_is_recorded_and_reported(tmp_path, monkeypatch):
    from pipeline.config import load_config
    from pipeline.workflow import commands
    from pipeline.workflow.library import library_rows, plan_library_part, read_record
    config = load_config()
    config["library"] = {"paths": [str(DRAWINGS)], "time_limit_s": 5}

    def boom(*args, **kwargs):
        raise RuntimeError("the planner fell over")
    monkeypatch.setattr(commands, "plan_command", boom)
    drawing = DRAWINGS / "triangle_right_50x30.dxf"
    rec = plan_library_part(config, drawing, "triangle_right_50x30.dxf#0", "tri", tmp_path / "parts" / "t-0")
    assert rec["status"] == "failed" and "the planner fell over" in rec["reason"]
    assert (tmp_path / "parts" / "t-0" / "part.svg").is_file()  # drawn before planning
    monkeypatch.setattr(commands, "plan_command", lambda *a, **k: (_ for _ in ()).throw(
        PinfeedError("pin radius 3 mm is too large for this part")))
    rec = plan_library_part(config, drawing, "triangle_right_50x30.dxf#0", "tri", tmp_path / "parts" / "t-1")
    assert rec["status"] == "refused" and rec["reason"] == "pin radius 3 mm is too large for this part"
    record = read_record("triangle_right_50x30.dxf", drawing, config["library"])
    record["parts"][0]["key"] = "t-1"
    rows = library_rows([record], {"t-1": tmp_path / "parts" / "t-1"}, tmp_path)
    assert [(r["class"], r["reason"]) for r in rows] == [("not readable", "pin radius 3 mm is too large for this part")]
    assert rows[0]["answer"].startswith("not readable (refused by the planner)")
