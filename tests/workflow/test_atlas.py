"""The feedability atlas: its rows against the plan files they summarise
(a part with holes among them), its CSV against its JSON, ``pinfeed atlas``,
the report's grid (thumbnails of every part, holes drawn), and planner.parts
naming families, ``all`` and bad names."""
import copy
import csv
import json

import pytest

from cli_runs import run_cli

from pipeline.config import load_config, validate_config
from pipeline.errors import PinfeedError
from pipeline.maps.io import write_json
from pipeline.parts.part import Part
from pipeline.workflow.atlas import COLUMNS, build_atlas, write_atlas
from pipeline.planning import PlannerSettings
from pipeline.workflow.commands import plan_tight_only

PARTS = {"right_triangle": [[0, 0], [50, 0], [0, 30]],
         "flat_bar": [[0, 0], [60, 0], [60, 12], [0, 12]],
         "holed_gusset": [[0, 0], [50, 0], [50, 6], [6, 40], [0, 40]]}
HOLES = {"holed_gusset": [[[5, 5], [11, 5], [11, 11], [5, 11]], [[17, 7], [31, 7], [31, 12], [17, 12]]]}


@pytest.fixture(scope="module")
def planned(tmp_path_factory):
    """Plan files of two parts made by the real planner (small settings), with a
    speed and a layout file for one of them."""
    root = tmp_path_factory.mktemp("atlas")
    config = load_config()
    config["catalog_dir"] = str(root / "catalog")
    pc = config["planner"]
    pc.update(depth=2, mu_c=0.15, frictions=[], tolerance_deg=12.0)
    pc["dynamic"].update(depth=0, speeds=[])
    config["verify"].update(trials=10, rule="point")
    paths = []
    for name, vertices in PARTS.items():
        path = root / "plans" / f"{name}.json"
        part = Part.from_vertices(vertices, name=name, holes=HOLES.get(name, ()))
        write_json(plan_tight_only(part, PlannerSettings.from_config(config), config["catalog_dir"]).to_dict(), path)
        paths.append(path)
    speed = write_json({"part": "right_triangle", "speed_limit_mm_s": 210.0}, root / "speed" / "right_triangle.json")
    layout = write_json({"part": "right_triangle", "belt_speed_mm_s": 168.0, "throughput_per_min": 55.5},
                        root / "layout_right_triangle.json")
    return config, root, paths, [speed], [layout]


def test_atlas_rows_match_the_plan_files(planned):
    config, root, paths, speeds, layouts = planned
    atlas = build_atlas(config, paths, speeds, layouts)
    assert [r["part"] for r in atlas["rows"]] == list(PARTS)
    for row, path in zip(atlas["rows"], paths):
        entry = json.loads(path.read_text())["tight"][0]
        rec = entry["recommended"]
        verdict = rec["verification"]["orientation"] if rec else {}
        assert row["plan"] == (" ".join(rec["pins"]) if rec else None)
        assert row["orients"] == bool(verdict.get("orients"))
        assert row["verified_width_deg"] == verdict.get("width_deg")
        assert row["in_set"] == verdict.get("in_tolerance") and row["trials"] == verdict.get("trials")
        assert row["tolerance_deg"] == 12.0
        if rec:
            assert row["fixed_pins"] + row["moving_pins"] == len(rec["pins"])
        assert row["sensor_needed"] == (not row["orients"])
        assert row["sets"] == (1 if row["orients"] else verdict.get("sets_within_tolerance"))
        assert row["evidence"] == entry["fixed_pin_search"]["evidence"]
    tri = atlas["rows"][0]
    assert (tri["speed_limit_mm_s"], tri["throughput_per_min"]) == (210.0, 55.5)
    assert atlas["rows"][1]["speed_limit_mm_s"] is None  # no speed file: left empty, not invented


def test_atlas_csv_matches_its_json_and_cli_prints_it(planned, capsys):
    config, root, paths, speeds, layouts = planned
    results = root / "results"
    write_atlas(build_atlas(config, paths, speeds, layouts), results / "atlas.json", results / "atlas.csv")
    stored = json.loads((results / "atlas.json").read_text())
    with open(results / "atlas.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == list(COLUMNS)
    for got, want in zip(rows, stored["rows"], strict=True):
        assert got == {k: "" if want[k] is None else str(want[k]) for k in COLUMNS}
    code, out, err = run_cli(capsys, ["atlas", "--results", str(results)])
    assert code == 0, err
    for row in stored["rows"]:
        assert any(line.startswith(row["part"]) and row["outcome"] in line for line in out.splitlines())
    code, out, _ = run_cli(capsys, ["atlas", "--results", str(results), "--json"])
    assert code == 0 and json.loads(out)["rows"] == stored["rows"]


def test_atlas_missing_is_one_line(tmp_path, capsys):
    code, out, err = run_cli(capsys, ["atlas", "--results", str(tmp_path)])
    assert code != 0 and "no atlas at" in err and "make run" in err and len(err.strip().splitlines()) == 1


def _config(parts, families=None):
    cfg = copy.deepcopy(load_config())
    if families is not None:
        cfg["families"] = families
    cfg["planner"]["parts"] = parts
    cfg["sensing"]["parts"] = []
    return cfg


def test_planner_parts_take_families_and_all():
    fams = {"a": {"parts": [{"name": "p1", "vertices": PARTS["right_triangle"]}]},
            "b": {"parts": [{"name": "p2", "vertices": PARTS["flat_bar"]},
                            {"name": "p3", "vertices": [[0, 0], [40, 0], [20, 60]]}]}}
    assert validate_config(_config(["b"], fams))["planner"]["parts"] == ["p2", "p3"]
    assert validate_config(_config(["all"], fams))["planner"]["parts"] == ["p1", "p2", "p3"]
    assert validate_config(_config(["p3", "b", "p1"], fams))["planner"]["parts"] == ["p3", "p2", "p1"]


@pytest.mark.parametrize("parts, families, words", [
    (["nope"], None, "nope is neither a part, a family nor 'all'"),
    (["empty"], {"empty": {"parts": []}, "a": {"parts": [{"name": "p1", "vertices": PARTS["flat_bar"]}]}},
     "family empty has no parts"),
])
def test_planner_parts_bad_names_are_one_line(parts, families, words):
    with pytest.raises(PinfeedError) as exc:
        validate_config(_config(parts, families))
    assert words in str(exc.value) and "\n" not in str(exc.value)


@pytest.mark.parametrize("bad", ["0", "-5", "360", "1e9"])
def test_plan_tolerance_out_of_range_is_one_line(bad, capsys):
    code, out, err = run_cli(capsys, ["plan", "--vertices", "0,0 50,0 0,30", f"--tolerance={bad}"])
    assert code != 0 and "tolerance" in err and len(err.strip().splitlines()) == 1


def test_report_atlas_grid_links_colours_and_labels(planned):
    """The report's atlas grid: one tile per part, linking to its section,
    framed by outcome, labelled from the same atlas row."""
    from html.parser import HTMLParser

    from pipeline.present.atlas_section import COLOURS, atlas_section
    config, root, paths, speeds, layouts = planned
    atlas = build_atlas(config, paths, speeds, layouts)
    html_text = "\n".join(atlas_section(atlas, {}, root, lambda name: f"part-{name}"))

    class Tiles(HTMLParser):
        def __init__(self):
            super().__init__()
            self.tiles = []

        def handle_starttag(self, tag, attrs):
            if tag == "a":
                self.tiles.append(dict(attrs))

    parser = Tiles()
    parser.feed(html_text)
    assert [t["href"] for t in parser.tiles] == [f"#part-{name}" for name in PARTS]
    for tile, row in zip(parser.tiles, atlas["rows"]):
        assert COLOURS[row["outcome"]] in tile["style"]
        words = f"{row['verified_width_deg']:.1f} deg" if row["orients"] else f"{row['sets']} sets"
        assert words in html_text


def test_the_nearest_yes_columns_read_the_plan_file():
    from pipeline.workflow.atlas import atlas_row
    axes = [{"axis": "inset", "found": True, "value": 0.26}, {"axis": "friction", "found": False},
            {"axis": "tolerance", "found": True, "value": 17.5}, {"axis": "moving pins", "found": False}]
    plan_file = {"part": {"name": "p", "id": "p-1"},
                 "tight": [{"recommended": None, "fixed_pin_search": {}, "nearest_yes": {"axes": axes}}]}
    row = atlas_row(plan_file)
    assert (row["nearest_inset_a"], row["nearest_mu_c"], row["nearest_tolerance_deg"],
            row["nearest_moving_pins"]) == (0.26, "none", 17.5, "none")
    plan_file["tight"][0].pop("nearest_yes")
    assert atlas_row(plan_file)["nearest_tolerance_deg"] is None


def test_an_axis_a_time_limit_cut_is_not_read_as_none():
    """"none" means the axis was searched and found nothing; an axis answered
    from the kept plans only, or cut by a time limit, is not known (None)."""
    from pipeline.workflow.atlas import atlas_row
    axes = [{"axis": "tolerance", "found": False, "kept_plans_only": True},
            {"axis": "moving pins", "found": False, "partial": True}]
    plan_file = {"part": {"name": "p", "id": "p-1"},
                 "tight": [{"recommended": None, "fixed_pin_search": {}, "nearest_yes": {"axes": axes}}]}
    row = atlas_row(plan_file)
    assert (row["nearest_tolerance_deg"], row["nearest_moving_pins"]) == (None, None)
    axes[0]["kept_plans_only"] = False
    assert atlas_row(plan_file)["nearest_tolerance_deg"] == "none"
