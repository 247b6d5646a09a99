"""One HTML page per config that links every result: a table of contents, then
a section per part (outline, maps, plans, verification, animation, sensing).

Every figure, JSON file and catalog shard is linked relatively from the page
(``RESULTS_DIR/NAME/report.html``); warnings and failing verification rows
come first, in red. Each table is shown once, its numbers read from the JSON
it links."""
from __future__ import annotations

import html
import os
from pathlib import Path

from pipeline import __version__
from pipeline.config import config_hash
from pipeline.maps.io import write_text_atomic
from pipeline.planning import SUBJECT_FAMILY, SUBJECT_PART, PlannerSettings, format_arcs, nearest_yes_lines
from pipeline.present.atlas_section import atlas_section
from pipeline.present.figures.tables import HEADER, verification_rows
from pipeline.present.layout import speed_limit_text
from pipeline.provenance import creation_time, git_commit

SECTIONS = (("outline", "Outline"), ("maps", "Configuration maps"), ("plans", "Plans"),
            ("verification", "Verification"), ("animation", "Animation"), ("layout", "Feeder layout"),
            ("sensing", "Sensing"), ("support", "Support distributions"))
STYLE = ("body{font-family:sans-serif;max-width:1100px;margin:2em auto}img{max-width:100%}.warn{color:#b00}"
         "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:3px 8px;font-size:90%}"
         "tr.fail td{background:#f8d0d0}.files{font-size:90%}")


def _rel(path, base):
    return html.escape(os.path.relpath(path, base))


def _anchor(name: str, section: str = "") -> str:
    return html.escape(f"part-{name}" + (f"-{section}" if section else ""))


def _link(path, base, text) -> str:
    return f'<a href="{_rel(path, base)}">{html.escape(text)}</a>'


def _figure(files: dict, kind: str, base, title: str) -> list[str]:
    """A figure under a heading, the image linking to its file; nothing if absent."""
    if kind not in files:
        return []
    src = _rel(files[kind], base)
    return [f"<h4>{html.escape(title)}</h4>",
            f'<a href="{src}"><img src="{src}" alt="{html.escape(title)}"></a>']


def config_title(config: dict) -> str:
    """The config in the page's heading: ``config workstation``, or ``the default
    config`` for the embedded one (named ``config`` after its file)."""
    name = config.get("name", "default")
    return "the default config" if name in ("config", "default") else f"config {name}"


def write_report(config, parts: dict, out, overview: dict | None = None, catalog=None,
                 atlas: dict | None = None) -> Path:
    """``parts``: name -> {"plan", "verify", optional "sensing" (results), "files"
    (kind -> path), "shards" (catalog entries)}; ``overview``: text -> path of the
    all-parts files; ``catalog``: the catalog folder (shard links); ``atlas``: the
    feedability atlas (``workflow.atlas``), shown first. Writes ``out``."""
    out = Path(out)
    base = out.parent
    pc, bc = config["planner"], config["bands"]
    p = ['<!doctype html><html><head><meta charset="utf-8">'
         f"<title>pinfeed results: {html.escape(config_title(config))}</title>"
         f"<style>{STYLE}</style></head><body>",
         f"<h1>pinfeed results: {html.escape(config_title(config))}</h1>",
         f"<p>pinfeed {html.escape(__version__)} ({html.escape(git_commit())}), config "
         f"{config_hash(config)}, made {creation_time()}. Planner: model "
         f"{html.escape(pc['model'])}, mu_c {html.escape(str(pc['mu_c']))}, depth "
         f"{pc['depth']}, orientation tolerance {pc.get('tolerance_deg', 10):g} deg, d in "
         f"[{pc['d_min']:g}, {pc['d_max']:g}], bands T = {bc['threshold_T']:g} deg, "
         f"c = {bc['factor_c']:g}.</p>"]
    if atlas:
        thumbs = {n: v["files"]["outline"] for n, v in parts.items() if "outline" in v["files"]}
        p += atlas_section(atlas, thumbs, base, _anchor)
    p += _warnings({n: v["plan"] for n, v in parts.items()}, {n: v["verify"] for n, v in parts.items()})
    p += _toc(parts)
    if overview:
        p.append('<p class="files">All parts: ' + ", ".join(
            _link(path, base, text) for text, path in overview.items()) + "</p>")
    for name, part in parts.items():
        p += _part_section(name, part, base, catalog, config)
    p.append("</body></html>")
    return write_text_atomic("\n".join(p), out)


def _toc(parts: dict) -> list[str]:
    """The table of contents: one entry per part, its sections beneath."""
    p = ['<nav id="toc"><h2>Contents</h2><ul>']
    for name in parts:
        subs = "".join(f'<li><a href="#{_anchor(name, key)}">{title}</a></li>' for key, title in SECTIONS
                       if key not in ("sensing", "layout", "support") or parts[name].get(key))
        p.append(f'<li class="toc-part"><a href="#{_anchor(name)}">{html.escape(name)}</a><ul>{subs}</ul></li>')
    return p + ["</ul></nav>"]


def _part_section(name: str, part: dict, base, catalog, config: dict) -> list[str]:
    """One part: its files, then outline, maps, plans, verification, animation, sensing."""
    res, ver, files = part["plan"], part["verify"], part["files"]
    p = [f'<h2 id="{_anchor(name)}">{html.escape(name)}</h2>',
         '<p class="files">Files: ' + ", ".join(
             _link(files[k], base, f"{k} JSON") for k in ("plan", "verify", "sensing", "speed", "support")
             if k in files) + "</p>"]
    if part.get("shards") and catalog is not None:
        p.append('<details class="files"><summary>Catalog shards of this part '
                 f'({len(part["shards"])})</summary><ul>' + "".join(
                     f"<li>{_link(Path(catalog) / e['file'], base, e['file'])}: {html.escape(e['model'])}, "
                     f"mu_c {e['mu_c']:g}, v_pin/v_b {e.get('v_pin', 0.0):+g}"
                     + (f", support {html.escape(e['support'])}" if e.get("support_key") else "")
                     + "</li>" for e in part["shards"])
                 + "</ul></details>")
    p.append(f'<h3 id="{_anchor(name, "outline")}">Outline</h3>')
    p.append(f"<p>Part id {html.escape(res['part']['id'])}; initial states: " + ", ".join(
        f"{html.escape(k)}: θ = {v['theta']:.1f}°, y_c = {v['y_c']:.2f} mm"
        for k, v in res["initial_states"].items()) + "</p>")
    p += _figure(files, "outline", base, "Outline, centroid and resting states")
    p.append(f'<h3 id="{_anchor(name, "maps")}">Configuration maps</h3>')
    p.append(f"<p>Maps: {html.escape(res['selection'])}.</p>")
    captions = part.get("captions", {})  # made from the records each figure is drawn from
    p += _figure(files, "maps", base, captions.get("maps", "Configuration maps with bands (rows: models)"))
    p += _figure(files, "speeds", base, captions.get("speeds", "Maps by pin speed (dynamic pins)"))
    p.append(f'<h3 id="{_anchor(name, "plans")}">Plans</h3>')
    p += _side_by_side(res, ver, part.get("speed"))
    p += _search_evidence(res)
    p += _paper_plans(res)
    for kind in ("sequence_tight", "sequence", "sequence_dynamic", "carried", "speed_limit"):
        p += _figure(files, kind, base, captions.get(kind, kind.replace("_", " ")))
    p.append(f'<h3 id="{_anchor(name, "verification")}">Verification</h3>')
    p += _verification_table(name, ver)
    p += _figure(files, "verification", base, "Verification by plan (failing states in red)")
    p.append(f'<h3 id="{_anchor(name, "animation")}">Animation</h3>')
    p += _animation(res, files, base, config, part.get("layout"))
    if part.get("layout"):
        p.append(f'<h3 id="{_anchor(name, "layout")}">Feeder layout</h3>')
        p += _layout_section(part["layout"], files, base, captions.get("layout_png"))
    if "sensing" in part:
        p.append(f'<h3 id="{_anchor(name, "sensing")}">Sensing</h3>')
        p += _sensing_section(part["sensing"], files, base)
    if "support" in part:
        p.append(f'<h3 id="{_anchor(name, "support")}">Support distributions</h3>')
        p += _support_section(part["support"], files, base)
    return p


def _support_section(res: dict, files: dict, base) -> list[str]:
    """The support study's three numbers: theta_f's shift from uniform to the
    family, whether the recommended plan survives it, the plan that does."""
    s, fam = res["spread"], res["family"]
    p = [f"<p>Support family <b>{html.escape(fam['label'])}</b> ({len(fam['members'])} members; "
         f"extremes {html.escape(', '.join(fam['extremes']))}).</p><ul>",
         f"<li><b>theta_f moves</b> between uniform pressure and the family by median "
         f"{s['shift_median_deg']} deg, p90 {s['shift_p90_deg']} deg, max {s['shift_max_deg']} deg "
         f"(largest shift of any member per map cell, over {s['cells_compared']} of {s['cells']} cells "
         f"of the sweep's grid at mu_c {', '.join(f'{m:g}' for m in s['frictions'])}; a passage's outcome "
         f"changes in {100 * s['outcome_changed_share']:.1f} % of the cells).</li>"]
    rec = " ".join(res.get("uniform_plan") or []) or "none"
    surv = res.get("survival")
    if res["survives"] is None:
        p.append("<li>No recommended plan to replay.</li>")
    else:
        o = (surv or {}).get("orientation")
        detail = (f": {o['in_tolerance']}/{o['trials']} trials in one set of {o['tolerance_deg']:g} deg "
                  f"(needs {o['needed']})") if o else " (no pin needed: resting states do not depend on support)"
        word = "survives" if res["survives"] else '<span class="warn">does not survive</span>'
        widen = res.get("widening") or {}
        if widen.get("uniform_width_deg") is not None and widen.get("family_width_deg") is not None:
            detail += (f"; its final set widens from {widen['uniform_width_deg']:.1f} deg (uniform) to "
                       f"{widen['family_width_deg']:.1f} deg (the narrowest arc holding the required share)")
        p.append(f"<li><b>The recommended plan {html.escape(rec)} {word}</b> the family at mu_c "
                 f"{html.escape(res['mu_c'])}{detail}.</li>")
    fp = res.get("family_plan")
    if fp:
        if fp.get("orients"):
            p.append(f"<li><b>The plan that does: {html.escape(' '.join(fp['pins']))}</b> (heights "
                     f"{', '.join(f'{y:g}' for y in fp['pin_heights_mm'])} mm). {_family_claim_text(fp)} "
                     f"{html.escape(fp['evidence'])}.</li>")
        else:
            p.append(f'<li class="warn">No plan orients the part for every member: '
                     f"{html.escape(fp.get('warning') or fp['evidence'])}</li>")
            if fp.get("nearest_yes"):
                head, *lines = nearest_yes_lines(fp["nearest_yes"], SUBJECT_FAMILY)  # a family plan's answer
                p.append(f"<li>{html.escape(head)}<ul>"
                         + "".join(f"<li>{html.escape(line.strip())}</li>" for line in lines) + "</ul></li>")
    p.append("</ul>")
    return p + _figure(files, "support_maps", base, "Configuration maps: uniform (black), the family (grey), "
                       "its extremes (colours)")


def _family_claim_text(fp: dict) -> str:
    """The family plan's one claim (an older study without one: its verdict on
    the family's trials), escaped."""
    if isinstance(fp.get("claim"), dict):
        from pipeline.planning import Claim
        return html.escape(f"Claim: {Claim.from_dict(fp['claim']).statement()}.")
    v = fp["verification"]["orientation"]
    return html.escape(f"{v['in_tolerance']}/{v['trials']} trials of the family in one arc of "
                       f"{v['tolerance_deg']:g} deg.")


def _layout_section(lay: dict, files: dict, base, caption: str | None = None) -> list[str]:
    """The feeder to build: throughput, speed limit, pitch, stations, the drawing."""
    if not lay.get("plan"):
        return [f"<p>{html.escape(lay.get('note', 'no layout'))}</p>"]
    tp, v = lay.get("throughput_per_min"), lay.get("belt_speed_mm_s")
    p = [f"<p>Plan {lay['plan']['number']} ({html.escape(' '.join(lay['plan']['pins']))}): "
         f"<b>throughput {'n/a' if tp is None else f'{tp:.1f}'} parts/min</b> at belt speed "
         f"{'n/a' if v is None else f'{v:.1f}'} mm/s ({html.escape(lay['method']['belt_speed'])}); "
         f"<b>speed limit {html.escape(speed_limit_text(lay))}</b>; pitch {lay['pitch_mm']:.1f} mm; belt "
         f"width {lay['belt_width_mm']:.1f} mm; model {html.escape(lay['method']['model'])}, "
         f"{lay['method']['trials']['replayed']} trials. Stations: " + ", ".join(
             f"{html.escape(s['label'])} at x = {s['x_mm']:.1f} mm, y = {s['y_mm']:g} mm"
             for s in lay["stations"]) + "</p>"]
    p += [f'<p class="warn">{html.escape(w)}</p>' for w in lay.get("warnings", [])]
    p.append('<p class="files">Drawing: ' + ", ".join(
        _link(files[k], base, k.replace("layout_", "").upper()) for k in
        ("layout_json", "layout_dxf", "layout_svg") if k in files) + "</p>")
    return p + _figure(files, "layout_png", base, caption or "Feeder drawing (top view)")


def _paper_plans(res: dict) -> list[str]:
    """Paper mode's ranked plans (adjusted bands), best first."""
    if not res["plans"]:
        return ["<p>Paper mode: no allowed plan within the depth.</p>"]
    p = ["<h4>Paper-mode plans (adjusted bands), best first</h4><table><tr><th>rank</th><th>pins</th>"
         "<th>heights (mm) @ speed (v_pin/v_b)</th><th>sets after each pin</th>"
         "<th>final sets</th><th>orientation sets</th><th>margin in d</th></tr>"]
    speeds = res.get("pin_speeds", {})
    for k, plan in enumerate(res["plans"], start=1):
        sets = format_arcs(plan["final_sets"])
        heights = ", ".join(f"{res['pins'][q]:g}" + (f" @ {speeds[q]:+g}" if q in speeds else "")
                            for q in plan["pins"])
        after = " → ".join(str(n) for n in plan.get("sets_after_each_pin", []))
        p.append(f"<tr><td>{k}</td><td>{' → '.join(plan['pins'])}</td><td>{heights}</td>"
                 f"<td>{after}</td><td>{plan['n_final_sets']}</td><td>{html.escape(sets)}</td>"
                 f"<td>{plan['margin']:.3f}</td></tr>")
    return p + ["</table>"]


def _verification_table(name: str, ver: dict) -> list[str]:
    """Every verified plan's rows (trials, successes, failures by reason); failing rows red."""
    rows = verification_rows({name: ver})
    if not rows:
        return [f"<p>Nothing verified: {html.escape(ver.get('note', 'no plan'))}.</p>"]
    fail = HEADER.index("failures")
    p = ['<table class="verification"><tr>' + "".join(f"<th>{h}</th>" for h in HEADER[1:]) + "</tr>"]
    for r in rows:
        cls = ' class="fail"' if r[fail] != "0" else ""
        p.append(f"<tr{cls}>" + "".join(f"<td>{html.escape(c)}</td>" for c in r[1:]) + "</tr>")
    return p + ["</table>"]


def _animation(res: dict, files: dict, base, config: dict, layout: dict | None) -> list[str]:
    """The part's animation, captioned from the records it was drawn from: the
    layout's plan, else the recommended plan (``animate.animation_subject``)."""
    from pipeline.present.animate import animation_subject
    if "animation" not in files:
        return ["<p>No animation.</p>"]
    what = animation_subject(res, PlannerSettings.from_config(config), layout)
    src = _rel(files["animation"], base)
    return [f"<p class=\"caption\">Every initial state past the pins of {html.escape(what)}; "
            f"'pinfeed animate --part {html.escape(res['part']['name'])}' makes a smoother one.</p>",
            f'<a href="{src}"><img src="{src}" alt="animation"></a>']


def _warnings(plans: dict, verifications: dict) -> list[str]:
    """Warnings and failing verification rows, in red, for the top of the page."""
    items = []
    for name, res in plans.items():
        for t in res.get("tight", []):
            if t.get("warning"):
                items.append(f"{name}, tight planner at mu_c {t['friction']}: {t['warning']}")
            if t.get("nearest_yes"):  # what would make it a "yes", axis by axis
                subject = SUBJECT_FAMILY if t.get("support_family") else SUBJECT_PART
                head, *lines = nearest_yes_lines(t["nearest_yes"], subject)
                items += [f"{name}, {head.rstrip(':')}: {line.strip()}" for line in lines]
    for name, ver in verifications.items():
        for check in ver.get("checks", []):
            for r in check["rows"]:
                if r["failures"]:
                    items.append(f"{name}, {check['kind']} ({' '.join(check['plan'])}), {r['state']}: "
                                 f"{r['failures']} of {r['trials']} trials failed "
                                 f"({'; '.join(f'{k}: {v}' for k, v in sorted(r['reasons'].items()))})")
    if not items:
        return []
    return (['<div style="color:#b00"><h2>Warnings</h2><ul>'] +
            [f"<li>{html.escape(t)}</li>" for t in items] + ["</ul></div>"])


def _counts(check) -> str:
    if check is None:
        return "not verified"
    t = sum(r["trials"] for r in check["rows"])
    ok = sum(r["successes"] for r in check["rows"])
    return f"{ok}/{t}"


def _speed_cell(speed: dict | None, friction: str, pins) -> str:
    """The speed limit of a tight plan, if the speed stage replayed this plan."""
    if not speed or speed.get("speed_limit_mm_s") is None:
        return "<td>n/a</td>"
    if speed.get("friction") != friction or list(speed.get("pin_labels", [])) != list(pins):
        return "<td>n/a</td>"
    return f"<td>{speed['speed_limit_mm_s']:g} ({speed['trials']} trials per state)</td>"


def _search_evidence(res: dict) -> list[str]:
    """What the complete fixed-pin search found at each friction (red where
    fixed pins cannot orient the part, and why)."""
    items = []
    for t in res.get("tight", []):
        search = t.get("fixed_pin_search")
        if search:
            style = "" if search["orients"] else ' style="color:#b00"'
            items.append(f"<li{style}>mu_c {html.escape(t['friction'])}: {html.escape(search['evidence'])}</li>")
    return ['<p>Fixed-pin search (complete to the depth, see the README):</p><ul class="evidence">',
            *items, "</ul>"] if items else []


def _width_cell(plan: dict) -> str:
    """The plan's one claim and how its trials were drawn (a plan file written
    before claims were records: its held-out verdict); red when the plan does
    not orient the part."""
    claim = plan.get("claim")
    if isinstance(claim, dict):
        from pipeline.planning import Claim
        c = Claim.from_dict(claim)
        text = f"{c.statement()}. Its trials: {c.trials_text()}" + "".join(
            f"; {n}" for n in _tails_notes(plan.get("verification") or {})[1:])
        return f"<td>{html.escape(text)}</td>" if c.orients else f"<td style='color:#b00'>{html.escape(text)}</td>"
    o = (plan.get("verification") or {}).get("orientation")
    if not o:
        return "<td>n/a</td>"
    width = "n/a" if o["width_deg"] is None else f"{o['width_deg']:.1f}"
    notes = []
    if (plan.get("verification") or {}).get("held_out"):
        notes.append("held-out trials")
    iv = o.get("width_interval_deg")
    if iv and iv[0] is not None and iv[1] is not None:
        notes.append(f"width {100 * o['confidence']:g} % interval {iv[0]:.1f}-{iv[1]:.1f} deg")
    if "share_lower_bound" in o:
        notes.append(f"share >= {100 * o['share_lower_bound']:.2f} % at {100 * o['confidence']:g} % confidence")
    notes += _tails_notes(plan.get("verification") or {})
    if not o["orients"]:
        notes.append("near miss: clears the point rule only" if o.get("point_rule")
                     else f"does not orient: {o['sets_within_tolerance']} sets")
    text = (f"{width}: {o['in_tolerance']}/{o['trials']} in {o['tolerance_deg']:g} deg"
            + (f" ({'; '.join(notes)})" if notes else ""))
    return f"<td>{html.escape(text)}</td>" if o["orients"] else f"<td style='color:#b00'>{html.escape(text)}</td>"


def _tails_notes(verification: dict) -> list[str]:
    """Where the claim's normals were cut, and the width on untruncated normals beside it."""
    sigma = verification.get("truncation_sigma")
    if sigma is None:
        return []
    u = verification.get("untruncated")
    notes = [f"{', '.join(u['normal']) if u else 'theta, mu_c'} normals cut at {sigma:g} sigma"]
    if u:
        width = "n/a" if u["width_deg"] is None else f"{u['width_deg']:.1f} deg"
        iv = u.get("width_interval_deg") or [None, None]
        if None not in iv:
            width += f" ({iv[0]:.1f}-{iv[1]:.1f})"
        verdict = "orients" if u["orients"] else "does not orient"
        notes.append(f"beside the claim, untruncated normals (random draws only, no box corners): width {width}, "
                     f"{u['in_one_set']}/{u['trials']} in one set, {verdict}")
    return notes


def _side_by_side(res: dict, ver: dict | None, speed: dict | None = None) -> list[str]:
    """The paper-mode plan beside the tight planner's, with verification counts
    and the speed limit (mm/s, dynamic model) of the plan the speed stage replayed."""
    checks = {c["kind"]: c for c in (ver or {}).get("checks", [])}
    p = ['<h4>Paper mode beside the tight planner</h4><table class="side-by-side"><tr><th>planner</th>'
         "<th>friction mu_c</th><th>pins (height, mm)</th><th>carried sets (count)</th>"
         "<th>carried sets (deg; not the claim)</th><th>replayed in the carried sets (successes/trials)</th>"
         "<th>the claim</th>"
         "<th>speed limit (mm/s)</th></tr>"]
    static = res.get("best_static")
    if static:
        pins = ", ".join(f"{q} ({res['pins'][q]:g})" for q in static["pins"])
        sets = format_arcs(static["final_sets"])
        p.append(f"<tr><td>paper mode, fixed pins</td><td>{res['mu_c']:g} (stored maps)</td>"
                 f"<td>{html.escape(pins)}</td><td>{static['n_final_sets']}</td><td>{sets}</td>"
                 f"<td>{_counts(checks.get('paper mode, fixed pins'))}</td><td>n/a</td><td>n/a</td></tr>")
    for t in res.get("tight", []):
        plan = t["recommended"]
        if plan is None:
            p.append(f"<tr><td>tight</td><td>{t['friction']}</td><td colspan=6 style='color:#b00'>"
                     f"{html.escape(t['warning'] or 'no plan')}</td></tr>")
            continue
        pins = ", ".join(f"{q} ({y:g})" for q, y in zip(plan["pins"], plan["pin_heights_mm"]))
        sets = format_arcs(plan["final_sets"])
        planner = "tight" + (f" at {t['belt_speed']:g} mm/s" if t.get("belt_speed") else "")
        p.append(f"<tr><td>{planner}</td><td>{t['friction']}</td><td>{html.escape(pins)}</td>"
                 f"<td>{plan['n_final_sets']}</td><td>{sets}</td>"
                 f"<td>{_counts(checks.get('tight, mu_c ' + t['friction']))}</td>"
                 f"{_width_cell(plan)}{_speed_cell(speed, t['friction'], plan['pins'])}</tr>")
    p.append("</table>")
    return p


def _sensing_section(res: dict, figs: dict, base) -> list[str]:
    """Force/torque sensor on the first pin: the verdict table and the two figures."""
    p = []
    if not res.get("found"):
        return p + [f"<p>No sensor plan: {html.escape(res.get('note', 'no stored verified plan'))}.</p>"]
    t = res["score_table"]
    known = ("a known final orientation for every initial state" if res["known_for_every_state"]
             else f"up to {res['worst_sets']} final orientation sets for one verdict")
    alone = res["without_sensor"]
    p.append(f"<p>Sensor on {html.escape(res['first_pin'])} (y = {res['y_pin']:g} mm), stored tight "
             f"plan #{res['plan_rank']} {html.escape(' → '.join(res['plan']['pins']))} at mu_c "
             f"{html.escape(res['friction'])} (simulated profiles at mu_c {res['mu_c_profiles']:g}): "
             f"{known}; {html.escape(res['note'])}. Without the sensor the recommended plan "
             f"{html.escape(' → '.join(alone['pins']))} ({alone['moving_pins']} moving pin(s)) ends in "
             f"{alone['n_final_sets']} set(s). Classification accuracy {100 * t['accuracy']:.0f} % "
             f"(wrong {100 * t['wrong']:.0f} %) over {t['trials']} synthetic measurements per state.</p>")
    p.append("<table><tr><th>sensor verdict (states it cannot tell apart)</th>"
             "<th>final orientation set(s) (deg)</th><th>known</th></tr>")
    for g in res["groups"]:
        sets = format_arcs(g["final_sets"], digits=0, style="interval")
        p.append(f"<tr><td>{html.escape(', '.join(g['states']))}</td><td>{sets}</td>"
                 f"<td>{'yes' if g['known'] else 'no'}</td></tr>")
    p.append("</table>")
    if "verification" in res:
        p.append("<p>End to end, perturbed full rollouts with the sensor reading the first pin "
                 "(trials counted by what the verdict said about the final orientation):</p>")
        p.append("<table><tr><th>initial state</th><th>trials</th><th>one set named, right</th>"
                 "<th>one set named, wrong</th><th>several sets named</th><th>jammed</th></tr>")
        for lab, r in res["verification"]["rows"].items():
            p.append(f"<tr><td>{html.escape(lab)}</td><td>{r['trials']}</td><td>{r['right']}</td>"
                     f"<td>{r['wrong']}</td><td>{r['ambiguous']}</td><td>{r['jammed']}</td></tr>")
        p.append("</table>")
    p += _figure(figs, "profiles", base, "Force/torque profiles on the first pin")
    p += _figure(figs, "scores", base, "Score matrix")
    return p
