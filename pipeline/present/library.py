"""The parts library's atlas: one row per part of every drawing, as JSON, CSV
and one HTML page (``RESULTS/library.html``) whose table sorts by any column
and filters by the answer (plain JavaScript in the page; nothing fetched).

Each row: a thumbnail with the part's holes, its size, its resting states,
the answer class (orients with N fixed pins, needs moving pins, needs the
sensor, "no" with its nearest "yes", not decided within the time limit, not
readable with its reason) and the claim's set and width, linking the part's
plan file, layout drawing and animation where they were made. A summary line
counts the parts in each class.
"""
from __future__ import annotations

import csv
import html
import io
import json
from pathlib import Path

COLUMNS = ("label", "drawing", "key", "class", "answer", "width_mm", "height_mm", "vertices", "holes",
           "resting_states", "fixed_pins", "moving_pins", "plan", "set_start_deg", "width_deg",
           "share_lower_bound", "sets", "complete", "nearest_yes", "reason", "planning_seconds",
           "thumbnail", "plan_file", "layout", "animation", "log")
# Answer classes, in the order the report sorts them.
CLASSES = ("fixed pins", "moving pins", "sensor", "no", "not decided", "not readable")
CLASS_TEXT = {"fixed pins": "orients with fixed pins", "moving pins": "needs moving pins",
              "sensor": "needs the sensor", "no": "no (see its nearest \"yes\")",
              "not decided": "not decided within the time limit", "not readable": "not readable"}
COLOURS = {"fixed pins": "#2a7d2a", "moving pins": "#c77c00", "sensor": "#b05000", "no": "#b00",
           "not decided": "#666", "not readable": "#555"}


def draw_thumbnail(part, out) -> Path:
    """A small SVG of the part (material filled, holes empty), axes off."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from matplotlib.patches import PathPatch

    from pipeline.present.figures.outline import part_path
    fig, ax = plt.subplots(figsize=(1.6, 1.6))
    ax.add_patch(PathPatch(part_path(part), facecolor="#9db7d5", edgecolor="#1f3b5a", lw=0.8))
    xy = part.vertices
    pad = 0.05 * max(float(np.ptp(xy[:, 0])), float(np.ptp(xy[:, 1])), 1e-9)
    ax.set_xlim(xy[:, 0].min() - pad, xy[:, 0].max() + pad)
    ax.set_ylim(xy[:, 1].min() - pad, xy[:, 1].max() + pad)
    ax.set_aspect("equal")
    ax.axis("off")
    fig.subplots_adjust(0, 0, 1, 1)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, format="svg", metadata={"Date": None}, transparent=True)
    plt.close(fig)
    return out


def class_counts(rows) -> dict:
    """Parts per answer class, in the classes' order (classes with none left out)."""
    counts = {c: 0 for c in CLASSES}
    for r in rows:
        counts[r["class"]] += 1
    return {c: n for c, n in counts.items() if n}


def summary_line(rows) -> str:
    """``N parts: a orient with fixed pins, b need moving pins, ...``."""
    counts = class_counts(rows)
    return f"{len(rows)} parts: " + ", ".join(f"{n} {CLASS_TEXT[c]}" for c, n in counts.items())


def library_csv(rows) -> str:
    """The rows as CSV text (header: :data:`COLUMNS`)."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=COLUMNS, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: "" if row.get(k) is None else row[k] for k in COLUMNS})
    return buf.getvalue()


# ---------------------------------------------------------------- the page

SCRIPT = """
var CLASS_ORDER = %(order)s;
function cellKey(td, col) {
  var v = td.getAttribute("data-sort");
  if (col === "class") return CLASS_ORDER.indexOf(v);
  var n = parseFloat(v);
  return isNaN(n) ? (v === "" ? Infinity : v.toLowerCase()) : n;
}
function sortBy(th) {
  var col = th.getAttribute("data-col"), table = document.getElementById("library");
  var idx = Array.prototype.indexOf.call(th.parentNode.children, th);
  var dir = th.getAttribute("data-dir") === "asc" ? "desc" : "asc";
  Array.prototype.forEach.call(th.parentNode.children, function (h) { h.removeAttribute("data-dir"); });
  th.setAttribute("data-dir", dir);
  var body = table.tBodies[0], rows = Array.prototype.slice.call(body.rows);
  rows.sort(function (a, b) {
    var x = cellKey(a.cells[idx], col), y = cellKey(b.cells[idx], col);
    var c = (typeof x === typeof y) ? (x < y ? -1 : x > y ? 1 : 0) : (typeof x === "number" ? -1 : 1);
    return dir === "asc" ? c : -c;
  });
  rows.forEach(function (r) { body.appendChild(r); });
  document.body.setAttribute("data-sorted", col + ":" + dir);
}
function filterBy(cls) {
  var shown = 0;
  Array.prototype.forEach.call(document.getElementById("library").tBodies[0].rows, function (r) {
    var on = !cls || r.getAttribute("data-class") === cls;
    r.style.display = on ? "" : "none";
    if (on) shown++;
  });
  document.body.setAttribute("data-shown", shown);
}
function fromHash() {
  var h = decodeURIComponent(location.hash.replace(/^#/, ""));
  h.split("&").forEach(function (kv) {
    var p = kv.split("=");
    if (p[0] === "sort") {
      var th = document.querySelector('th[data-col="' + p[1] + '"]');
      if (th) { th.click(); if (p[2] === "desc") th.click(); }
    }
    if (p[0] === "filter") { var s = document.getElementById("filter"); s.value = p[1]; filterBy(p[1]); }
  });
}
document.addEventListener("DOMContentLoaded", function () {
  Array.prototype.forEach.call(document.querySelectorAll("th[data-col]"), function (th) {
    th.addEventListener("click", function () { sortBy(th); });
  });
  document.getElementById("filter").addEventListener("change", function (e) { filterBy(e.target.value); });
  fromHash();
});
"""
STYLE = ("body{font-family:sans-serif;margin:1.5em}table{border-collapse:collapse}"
         "td,th{border:1px solid #ccc;padding:3px 6px;font-size:90%;vertical-align:middle}"
         "th[data-col]{cursor:pointer;background:#eee}th[data-dir=asc]::after{content:' \\25B2'}"
         "th[data-dir=desc]::after{content:' \\25BC'}td.thumb img{width:90px;height:90px}"
         ".cls{font-weight:bold}")
HEADERS = (("label", "part"), ("thumb", ""), ("size", "size (mm)"), ("resting_states", "resting states"),
           ("class", "answer"), ("set", "claim: set (deg)"), ("width_deg", "width (deg)"),
           ("files", "files"))


def _td(value, sort=None, cls="", inner=None) -> str:
    sort = "" if sort is None else str(sort)
    text = html.escape("" if value is None else str(value)) if inner is None else inner
    return f'<td{f" class={chr(34)}{cls}{chr(34)}" if cls else ""} data-sort="{html.escape(sort)}">{text}</td>'


def _html_row(r: dict) -> str:
    def link(path, text):
        return f'<a href="{html.escape(path)}">{html.escape(text)}</a>' if path else ""
    thumb = (f'<img src="{html.escape(r["thumbnail"])}" alt="{html.escape(r["label"])}">'
             if r.get("thumbnail") else "")
    size = "" if r.get("width_mm") is None else f"{r['width_mm']:.0f} x {r['height_mm']:.0f}"
    area = "" if r.get("width_mm") is None else r["width_mm"] * r["height_mm"]
    cset = "" if r.get("set_start_deg") is None else f"{r['set_start_deg']:.1f} + {r['width_deg']:.1f}"
    width = "" if r.get("width_deg") is None else f"{r['width_deg']:.1f}"
    bound = ("" if r.get("share_lower_bound") is None else
             f" (>= {100 * r['share_lower_bound']:.1f} % in one set)")
    files = " ".join(x for x in (link(r.get("plan_file"), "plan"), link(r.get("layout"), "layout"),
                                 link(r.get("animation"), "animation"), link(r.get("log"), "log")) if x)
    colour = COLOURS[r["class"]]
    return (f'<tr data-class="{html.escape(r["class"])}" id="{html.escape(r["key"])}">'
            + _td(r["label"], r["label"])
            + _td(None, "", "thumb", thumb)
            + _td(size, area)
            + _td(r.get("resting_states"), r.get("resting_states"))
            + _td(None, r["class"], "cls", f'<span style="color:{colour}">{html.escape(r["answer"])}</span>')
            + _td(cset, r.get("set_start_deg"))
            + _td(None, r.get("width_deg"), inner=html.escape(width + bound))
            + _td(None, "", inner=files) + "</tr>")


def library_page(rows, title: str, note: str = "") -> str:
    """The library's HTML page (one table; sort by a header's click, filter by answer)."""
    counts = class_counts(rows)
    options = "".join(f'<option value="{html.escape(c)}">{html.escape(CLASS_TEXT[c])} ({n})</option>'
                      for c, n in counts.items())
    heads = "".join(f'<th data-col="{c}">{html.escape(t)}</th>' if c not in ("thumb", "files") else
                    f"<th>{html.escape(t)}</th>" for c, t in HEADERS)
    return ("<!doctype html><html><head><meta charset=\"utf-8\">"
            f"<title>{html.escape(title)}</title><style>{STYLE}</style>"
            f"<script>{SCRIPT % {'order': json.dumps(list(CLASSES))}}</script></head><body>"
            f"<h1>{html.escape(title)}</h1>"
            f'<p id="summary">{html.escape(summary_line(rows))}</p>'
            + (f"<p>{html.escape(note)}</p>" if note else "")
            + '<p>Show: <select id="filter"><option value="">every part</option>' + options + "</select>"
            " &middot; click a column's header to sort by it "
            '(also <a href="library.csv">CSV</a>, <a href="library.json">JSON</a>)</p>'
            f'<table id="library"><thead><tr>{heads}</tr></thead><tbody>'
            + "".join(_html_row(r) for r in rows) + "</tbody></table></body></html>\n")


def write_library(rows, out_html, out_json, out_csv, meta: dict) -> dict:
    """Write the library's page, JSON (``meta``, ``summary``, ``counts``, ``rows``)
    and CSV, each atomically; returns the JSON document."""
    from pipeline.maps.io import write_json, write_text_atomic
    doc = {**meta, "summary": summary_line(rows), "counts": class_counts(rows), "columns": list(COLUMNS),
           "rows": rows}
    write_json(doc, out_json)
    write_text_atomic(library_csv(rows), out_csv)
    note = (f"Each part planned by the tight planner under a time limit of {meta['time_limit_s']:g} s "
            f"(a \"no\" or \"not decided\" under a limit covers only the sequences searched); tolerance "
            f"{meta['tolerance_deg']:g} deg, depth {meta['depth']}.") if meta.get("time_limit_s") else ""
    write_text_atomic(library_page(rows, f"pinfeed parts library: {meta.get('name')}", note), out_html)
    return doc
