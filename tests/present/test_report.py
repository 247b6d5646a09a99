"""The workflow's report page on a tiny config: every link and image resolves,
one TOC entry per part, numbers as in the JSON linked; results per config."""
import json
from html.parser import HTMLParser
from pathlib import Path

import pytest
import yaml
from workflow_runs import run_snakemake as _snakemake

from pipeline.config import config_name, load_config, results_folder, validate_config

TINY = {
    "catalog_dir": "cat", "results_dir": "res",
    "families": {"fam": {"parts": [{"name": "tri", "vertices": [[0, 0], [60, 0], [15, 35]]},
                                   {"name": "rect", "vertices": [[0, 0], [40, 0], [40, 20], [0, 20]]}]}},
    "sweep": {"models": ["ellipsoid"], "mu_c": [0.2], "v_pin": [0.0],
              "d": [-0.8, -0.6, -0.4, -0.2, 0.2, 0.4, 0.6, 0.8], "theta_step": 10, "pin_radius": 3.0},
    "planner": {"parts": ["tri", "rect"], "model": "ellipsoid", "mu_c": 0.2, "depth": 1,
                "pins": [-10, -5, 0, 5, 10, 15, 20, 25, 30, 35, 40], "dynamic": {"speeds": []}},
    "verify": {"trials": 3, "rule": "point"}, "sensing": {"trials": 3, "parts": ["tri"]},
    "speed": {"trials": 3, "speeds": [50, 200]},
    "figures": {"d": [0.4], "animation_frames": 3, "animation_fps": 2},
}


class _Page(HTMLParser):
    """Links, images, ids, TOC entries and table rows of a page."""

    def __init__(self):
        super().__init__()
        self.links, self.images, self.ids, self.toc = [], [], set(), []
        self.rows, self._row, self._cell, self._in_toc_part = {}, None, None, False
        self._table = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "a" and "href" in a:
            self.links.append(a["href"])
            if self._in_toc_part:
                self.toc.append(a["href"])
                self._in_toc_part = False
        if tag == "img":
            self.images.append(a["src"])
        if tag == "li" and a.get("class") == "toc-part":
            self._in_toc_part = True
        if tag == "table":
            self._table = a.get("class", "table")
            self.rows.setdefault(self._table, [])
        if tag == "tr":
            self._row = []
        if tag in ("td", "th"):
            self._cell = ""

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._row is not None:
            self._row.append(self._cell.strip())
            self._cell = None
        if tag == "tr" and self._row is not None:
            self.rows[self._table].append(self._row)
            self._row = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell += data


@pytest.fixture(scope="module")
def workflow(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("report")
    (tmp / "tiny.yaml").write_text(yaml.safe_dump(TINY))
    run = _snakemake(tmp, "--configfile", str(tmp / "tiny.yaml"))
    assert run.returncode == 0, run.stderr[-3000:]
    return tmp


def test_report_links_resolve_and_toc_has_one_entry_per_part(workflow):
    results = workflow / "res" / "tiny"
    page = _Page()
    page.feed((results / "report.html").read_text())
    assert page.toc == ["#part-tri", "#part-rect"]
    for href in page.links + page.images:
        if href.startswith("#"):
            assert href[1:] in page.ids, href
        else:
            assert (results / href).is_file(), href
    files = {str((results / h).resolve().relative_to(workflow.resolve())) for h in page.links + page.images}
    for name in ("tri", "rect"):  # every figure, JSON file and shard of each part is linked
        for want in (f"res/tiny/plans/{name}.json", f"res/tiny/verify/{name}.json",
                     f"res/tiny/animations/{name}.gif", f"res/tiny/speed/{name}.json",
                     *(f"res/tiny/figures/{k}_{name}.png" for k in
                       ("outline", "maps", "speeds", "sequence", "sequence_dynamic", "carried", "verification",
                        "speed_limit"))):
            assert want in files, want
        shards = {p.relative_to(workflow).as_posix() for p in (workflow / "cat" / "fam").rglob("*.h5")
                  if f"/{name}-" in p.as_posix()}
        assert shards and shards <= files
    assert {"res/tiny/sensing/tri.json", "res/tiny/figures/profiles_tri.png"} <= files
    assert "res/tiny/sensing/rect.json" not in files


def test_report_numbers_match_the_verify_json(workflow):
    results = workflow / "res" / "tiny"
    page = _Page()
    page.feed((results / "report.html").read_text())
    table = [r for r in page.rows["verification"] if r[0] != "plan"]
    want = []
    for name in ("tri", "rect"):
        for check in json.loads((results / "verify" / f"{name}.json").read_text())["checks"]:
            want += [[" ".join(check["plan"]), check["kind"], r["state"], str(r["trials"]),
                      str(r["successes"]), str(r["failures"])] for r in check["rows"]]
    assert [r[:6] for r in table] == want and want
    side = [r for r in page.rows["side-by-side"] if r[0] != "planner" and len(r) == 8]  # tri's rows, then rect's
    want, limits = [], []
    for name in ("tri", "rect"):
        plan = json.loads((results / "plans" / f"{name}.json").read_text())
        speed = json.loads((results / "speed" / f"{name}.json").read_text())
        if plan["tight"][0]["recommended"]:  # the speed stage replays the first friction's plan
            assert speed["pin_labels"] == plan["tight"][0]["recommended"]["pins"]
            limits.append(f"{speed['speed_limit_mm_s']:g} ({speed['trials']} trials per state)")
        else:
            assert speed["speed_limit_mm_s"] is None
        checks = {c["kind"]: c for c in json.loads((results / "verify" / f"{name}.json").read_text())["checks"]}
        rows = [("paper mode, fixed pins", plan["best_static"])]
        rows += [(f"tight, mu_c {t['friction']}", t["recommended"]) for t in plan["tight"] if t["recommended"]]
        for kind, best in rows:
            ok = sum(r["successes"] for r in checks[kind]["rows"])
            want.append([str(best["n_final_sets"]), f"{ok}/{sum(r['trials'] for r in checks[kind]['rows'])}"])
    assert [[r[3], r[5]] for r in side] == want
    assert [r[7] for r in side if r[0].startswith("tight") and r[7] != "n/a"] == limits
    cells = []  # the recommended plan's one claim, from the plan file, with its trials
    for name in ("tri", "rect"):
        for t in json.loads((results / "plans" / f"{name}.json").read_text())["tight"]:
            claim = (t["recommended"] or {}).get("claim")
            if claim:
                cells.append((claim["statement"], [f"{claim['in_arc']}/{claim['trials']} held-out trials",
                                                   f"seed {claim['trials_drawn']['seed']}"]))
    shown = [r[6] for r in side if r[0].startswith("tight")]
    assert len(shown) == len(cells) and cells
    assert all(cell.startswith(head) for cell, (head, _) in zip(shown, cells))
    assert all(note in cell for cell, (_, notes) in zip(shown, cells) for note in notes)
    assert all(int(r[3]) == 3 + 2 ** (3 + len(r[0].split())) for r in table)  # verify.trials 3 + corners


def test_standard_snakemake_report_has_the_figures(workflow):
    run = _snakemake(workflow, "--configfile", str(workflow / "tiny.yaml"), "--report", "std.zip")
    assert run.returncode == 0, run.stderr[-3000:]
    import zipfile
    names = zipfile.ZipFile(workflow / "std.zip").namelist()
    for stem in ("outline_tri", "maps_rect", "verification_tri", "profiles_tri", "speed_limit_tri"):
        assert any(n.endswith(f"{stem}.png") for n in names), stem
    assert any(n.endswith("tri.gif") for n in names)


def test_results_folder_is_named_after_the_config(tmp_path):
    (tmp_path / "my plant.yaml").write_text(yaml.safe_dump(TINY))
    assert config_name(tmp_path / "my plant.yaml") == "my_plant"
    assert results_folder(load_config(tmp_path / "my plant.yaml")) == Path("res/my_plant")
    assert results_folder(validate_config(dict(TINY, name="line2"))) == Path("res/line2")
    assert results_folder(validate_config(TINY)) == Path("res/default")
    from pipeline.errors import PinfeedError
    with pytest.raises(PinfeedError, match="config error at name"):
        validate_config(dict(TINY, name="../up"))


def test_two_configs_write_to_their_own_folders(tmp_path):
    for stem in ("a", "b"):
        (tmp_path / f"{stem}.yaml").write_text(yaml.safe_dump(TINY))
    a, b = (_planned_outputs(tmp_path, s) for s in ("a", "b"))
    assert {"res/a/report.html", "res/a/plans/tri.json", "res/a/verify/tri.json",
            "res/a/sensing/tri.json", "res/a/animations/tri.gif"} <= a
    assert "res/b/report.html" in b and not a & b


def _planned_outputs(workdir, stem) -> set:
    """Output files a dry run of config ``stem`` would write outside the shared catalog."""
    run = _snakemake(workdir, "--configfile", str(workdir / f"{stem}.yaml"), "--dry-run", "--summary")
    assert run.returncode == 0, run.stderr[-2000:]
    rows = [line.split("\t")[0] for line in run.stdout.splitlines()]
    return {r for r in rows if "/" in r and not r.startswith("cat/")}


def test_captions_come_from_the_records_their_figures_draw(workflow):
    """Each caption names the plan its figure draws, read here from the JSON the
    figure rules read: the plan file, the layout and the speed stage's result."""
    results = workflow / "res" / "tiny"
    page = (results / "report.html").read_text()
    assert "<h1>pinfeed results: config tiny</h1>" in page
    for name in ("tri", "rect"):
        plan = json.loads((results / "plans" / f"{name}.json").read_text())
        tight = plan["tight"][0]
        rec, static = tight["recommended"], plan["best_static"]
        if rec:
            assert (f"Pin sequence: recommended tight plan at mu_c {tight['friction']}: "
                    f"{' → '.join(rec['pins'])}") in page
            assert (results / "figures" / f"sequence_tight_{name}.png").is_file()
            assert f'src="figures/sequence_tight_{name}.png"' in page
        if static:
            assert f"Pin sequence: best fixed-pin plan (paper mode): {' → '.join(static['pins'])}" in page
        layout = json.loads((results / f"layout_{name}.json").read_text())
        if layout.get("plan"):
            p = layout["plan"]
            assert f"the laid-out tight plan {p['number']} at mu_c {p['friction']}" in page
            assert f"Feeder drawing (top view) of tight plan {p['number']}: {' → '.join(p['pins'])}" in page
        speed = json.loads((results / "speed" / f"{name}.json").read_text())
        if speed["speed_limit_mm_s"] is not None:
            assert (f"of tight plan {' → '.join(speed['pin_labels'])} at mu_c {speed['friction']}: speed "
                    f"limit {speed['speed_limit_mm_s']:g} mm/s ({speed['trials']} trials per state)") in page
            stored = plan["tight"][0]["plans"][0]["speed_limit"]  # one speed limit per plan
            assert (stored["speed_limit_mm_s"], stored["trials"]) == (speed["speed_limit_mm_s"], speed["trials"])


def test_default_config_heading_names_it_once():
    from pipeline.present.report import config_title
    assert config_title({"name": "config"}) == "the default config"
    assert config_title({"name": "workstation"}) == "config workstation"


def test_catalog_index_then_dry_run_has_nothing_to_do(workflow, capsys):
    """Re-indexing the catalog rewrites index.json; plans depend on their part's
    shards (the index only as 'ancient'), so nothing is re-planned. Last in this
    module: it touches the shared workflow folder."""
    from pipeline.cli import main
    assert main(["catalog", "index", "--catalog", str(workflow / "cat")]) == 0
    again = _snakemake(workflow, "--configfile", str(workflow / "tiny.yaml"), "--dry-run")
    assert again.returncode == 0, again.stderr[-2000:]
    assert "Nothing to be done" in again.stdout + again.stderr, (again.stdout + again.stderr)[-3000:]
