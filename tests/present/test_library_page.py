"""The parts library's page in a real browser (headless Chromium): every image
decodes and every link names a file that is there, a click on the answer
column's header sorts the rows by answer class (both ways), and the filter
shows one class; the summary line counts each class. Skipped where Chromium
is not installed (.ci/run installs the Debian packages chromium and
chromium-driver)."""
from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from pipeline.parts.part import Part
from pipeline.present.library import CLASSES, COLUMNS, draw_thumbnail, summary_line, write_library

FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--allow-file-access-from-files", "--virtual-time-budget=5000"]
# Appended to a copy of the page: after load (and the hash's sort), how many images decoded and the row order.
PROBE = """<script>window.addEventListener("load", function () {
  var imgs = Array.from(document.images);
  var ok = imgs.filter(function (i) { return i.complete && i.naturalWidth > 0; }).length;
  document.body.setAttribute("data-images", ok + "/" + imgs.length);
  var order = Array.from(document.getElementById("library").tBodies[0].rows).filter(function (r) {
    return r.style.display !== "none"; }).map(function (r) { return r.getAttribute("data-class"); });
  document.body.setAttribute("data-order", JSON.stringify(order));
});</script>"""
# (label, class) in an order that is not the classes' order
PARTS = [("plate.dxf#0", "not readable"), ("tri.dxf#0", "fixed pins"), ("sheet.dxf#0", "no"),
         ("sheet.dxf#1", "sensor"), ("cam.svg#0", "not decided"), ("lever.dxf#0", "moving pins"),
         ("tab.dxf#0", "fixed pins")]


def chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if shutil.which(name):
            return shutil.which(name)
    pytest.skip("no Chromium on this machine (.ci/run installs the Debian package chromium)")


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    """A library page of seven parts, one or more of each class, with thumbnails,
    plan files and a layout drawing on disk."""
    root = tmp_path_factory.mktemp("library_page")
    rows = []
    for k, (label, cls) in enumerate(PARTS):
        key = label.replace("#", "-")
        row = {c: None for c in COLUMNS}
        row.update(label=label, drawing=label.split("#")[0], key=key, answer=f"{cls}: row {k}", reason=None)
        row["class"] = cls
        if cls != "not readable":
            folder = root / "library" / "parts" / key
            draw_thumbnail(Part.from_vertices([[0, 0], [30 + 5 * k, 0], [10, 20]], name="p",
                                              holes=[[[8, 4], [12, 4], [12, 8], [8, 8]]]), folder / "part.svg")
            (folder / "plan.json").write_text("{}")
            row.update(thumbnail=f"library/parts/{key}/part.svg", plan_file=f"library/parts/{key}/plan.json",
                       width_mm=30.0 + 5 * k, height_mm=20.0, resting_states=3)
            if cls == "fixed pins":
                (folder / "layout.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"/>')
                row.update(layout=f"library/parts/{key}/layout.svg", width_deg=4.0 + k, set_start_deg=80.0)
        else:
            row["reason"] = "open outline"
        rows.append(row)
    meta = {"name": "test", "time_limit_s": 20, "tolerance_deg": 10, "depth": 2}
    write_library(rows, root / "library.html", root / "library.json", root / "library.csv", meta)
    return root, rows


def render(page: Path, profile: Path, fragment: str = "") -> str:
    probed = page.with_name("_probe_" + page.name)
    probed.write_text(page.read_text().replace("</body>", PROBE + "</body>"))
    run = subprocess.run([chromium(), *FLAGS, f"--user-data-dir={profile}", "--dump-dom",
                          probed.as_uri() + fragment], capture_output=True, text=True, timeout=120)
    return run.stdout


def attribute(dom: str, name: str) -> str:
    found = re.search(rf'{name}="([^"]*)"', dom)
    assert found, f"the page did not finish loading:\n{dom[:500]}"
    return found.group(1).replace("&quot;", '"')


def test_images_decode_and_links_resolve(page, tmp_path):
    root, rows = page
    dom = render(root / "library.html", tmp_path / "profile")
    loaded, total = map(int, attribute(dom, "data-images").split("/"))
    assert loaded == total == sum(r["thumbnail"] is not None for r in rows)
    links = re.findall(r'(?:href|src)="([^"#]+)"', dom)
    assert {"library.csv", "library.json"} <= set(links)
    assert sum(link.endswith("plan.json") for link in links) == 6 and any(link.endswith("layout.svg") for link in links)
    assert [link for link in links if not (root / link).is_file()] == []


@pytest.mark.parametrize("direction", ["asc", "desc"])
def test_a_click_on_the_answer_header_sorts_by_class(page, tmp_path, direction):
    root, _ = page
    fragment = "#sort=class" + ("=desc" if direction == "desc" else "")
    dom = render(root / "library.html", tmp_path / "profile", fragment)
    assert attribute(dom, "data-sorted") == f"class:{direction}"
    order = json.loads(attribute(dom, "data-order"))
    ranks = [CLASSES.index(c) for c in order]
    assert ranks == sorted(ranks, reverse=direction == "desc") and len(order) == len(PARTS)


def test_the_filter_shows_one_class_and_the_summary_counts(page, tmp_path):
    root, rows = page
    dom = render(root / "library.html", tmp_path / "profile", "#filter=fixed%20pins")
    assert json.loads(attribute(dom, "data-order")) == ["fixed pins", "fixed pins"]
    assert summary_line(rows) == ("7 parts: 2 orients with fixed pins, 1 needs moving pins, 1 needs the sensor, "
                                  "1 no (see its nearest \"yes\"), 1 not decided within the time limit, "
                                  "1 not readable")
    assert json.loads((root / "library.json").read_text())["counts"] == {
        "fixed pins": 2, "moving pins": 1, "sensor": 1, "no": 1, "not decided": 1, "not readable": 1}
