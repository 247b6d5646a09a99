"""One HTML page that links every result: maps, plans, sequence diagrams, verification."""
from __future__ import annotations

import html
import os
from pathlib import Path

from . import __version__
from .config import config_hash
from .figures.tables import HEADER, verification_rows
from .io import write_text_atomic
from .provenance import creation_time, git_commit


def _rel(path, base):
    return html.escape(os.path.relpath(path, base))


def write_report(config, plans: dict, verifications: dict, figures: dict, out,
                 sensing: dict | None = None) -> Path:
    """``plans``/``verifications``/``sensing``: part -> result dict; ``figures``: part ->
    {kind: path} plus key ``"verification"``. Writes ``out`` (HTML)."""
    sensing = sensing or {}
    out = Path(out)
    base = out.parent
    p = ['<!doctype html><html><head><meta charset="utf-8"><title>pinfeed results</title>',
         "<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto}"
         "img{max-width:100%}table{border-collapse:collapse}td,th{border:1px solid #ccc;"
         "padding:3px 8px;font-size:90%}</style></head><body>",
         "<h1>pinfeed results</h1>",
         f"<p>pinfeed {html.escape(__version__)} ({html.escape(git_commit())}), config "
         f"{config_hash(config)}, made {creation_time()}. Planner: model "
         f"{html.escape(config['planner']['model'])}, mu_c {html.escape(str(config['planner']['mu_c']))}, depth "
         f"{config['planner']['depth']}, d in [{config['planner']['d_min']:g}, "
         f"{config['planner']['d_max']:g}], T = {config['bands']['threshold_T']:g} deg, "
         f"c = {config['bands']['factor_c']:g}.</p>"]
    p += _warnings(plans, verifications)
    if "verification" in figures:
        p.append("<h2>Verification (full rollouts, perturbed)</h2>")
        p.append(f'<img src="{_rel(figures["verification"], base)}" alt="verification table">')
    for name, res in plans.items():
        p.append(f"<h2>{html.escape(name)}</h2>")
        p.append(f"<p>maps: {html.escape(res['selection'])}; initial states: " + ", ".join(
            f"{html.escape(k)}: θ = {v['theta']:.1f}°, y_c = {v['y_c']:.2f} mm"
            for k, v in res["initial_states"].items()) + "</p>")
        figs = figures.get(name, {})
        if "maps" in figs:
            p.append(f'<h3>Configuration maps with bands</h3><img src="{_rel(figs["maps"], base)}">')
        if "speeds" in figs:
            p.append(f'<h3>Maps by pin speed (dynamic pins)</h3><img src="{_rel(figs["speeds"], base)}">')
        p += _side_by_side(res, verifications.get(name))
        if "carried" in figs:
            p.append(f'<h3>Carried sets against replayed rollouts (recommended plan)</h3>'
                     f'<img src="{_rel(figs["carried"], base)}">')
        p.append("<h3>Paper-mode plans (adjusted bands), best first</h3><table><tr><th>rank</th><th>pins</th>"
                 "<th>heights (mm) @ speed (v_pin/v_b)</th><th>sets after each pin</th>"
                 "<th>final sets</th><th>orientation sets (deg)</th><th>margin in d</th></tr>")
        speeds = res.get("pin_speeds", {})
        for k, plan in enumerate(res["plans"], start=1):
            sets = ", ".join(f"[{s['start']:.0f}, {s['start'] + s['width']:.0f}]" for s in plan["final_sets"])
            heights = ", ".join(f"{res['pins'][q]:g}" + (f" @ {speeds[q]:+g}" if q in speeds else "")
                                for q in plan["pins"])
            after = " → ".join(str(n) for n in plan.get("sets_after_each_pin", []))
            p.append(f"<tr><td>{k}</td><td>{' → '.join(plan['pins'])}</td><td>{heights}</td>"
                     f"<td>{after}</td><td>{plan['n_final_sets']}</td><td>{sets}</td>"
                     f"<td>{plan['margin']:.3f}</td></tr>")
        p.append("</table>")
        if "sequence" in figs:
            p.append(f'<h3>Pin sequence: fixed pins</h3><img src="{_rel(figs["sequence"], base)}">')
        if "sequence_dynamic" in figs:
            p.append(f'<h3>Pin sequence: with dynamic pins</h3>'
                     f'<img src="{_rel(figs["sequence_dynamic"], base)}">')
        if name in verifications:
            rows = verification_rows({name: verifications[name]})
            p.append("<table><tr>" + "".join(f"<th>{h}</th>" for h in HEADER) + "</tr>")
            p += ["<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in rows]
            p.append("</table>")
        if name in sensing:
            p += _sensing_section(sensing[name], figs, base)
    p.append("</body></html>")
    return write_text_atomic("\n".join(p), out)


def _warnings(plans: dict, verifications: dict) -> list[str]:
    """Warnings and failing verification rows, in red, for the top of the page."""
    items = []
    for name, res in plans.items():
        for t in res.get("tight", []):
            if t.get("warning"):
                items.append(f"{name}, tight planner at mu_c {t['friction']}: {t['warning']}")
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


def _side_by_side(res: dict, ver: dict | None) -> list[str]:
    """The paper-mode plan beside the tight planner's, with verification counts."""
    from .arcs import format_arcs
    checks = {c["kind"]: c for c in (ver or {}).get("checks", [])}
    p = ["<h3>Plans: paper mode beside the tight planner</h3><table><tr><th>planner</th>"
         "<th>friction mu_c</th><th>pins (height, mm)</th><th>final sets</th>"
         "<th>orientation sets</th><th>verified (successes/trials)</th></tr>"]
    static = res.get("best_static")
    if static:
        pins = ", ".join(f"{q} ({res['pins'][q]:g})" for q in static["pins"])
        sets = format_arcs([(s["start"], s["width"]) for s in static["final_sets"]])
        p.append(f"<tr><td>paper mode, fixed pins</td><td>{res['mu_c']:g} (stored maps)</td>"
                 f"<td>{html.escape(pins)}</td><td>{static['n_final_sets']}</td><td>{sets}</td>"
                 f"<td>{_counts(checks.get('paper mode, fixed pins'))}</td></tr>")
    for t in res.get("tight", []):
        plan = t["recommended"]
        if plan is None:
            p.append(f"<tr><td>tight</td><td>{t['friction']}</td><td colspan=4 style='color:#b00'>"
                     f"{html.escape(t['warning'] or 'no plan')}</td></tr>")
            continue
        pins = ", ".join(f"{q} ({y:g})" for q, y in zip(plan["pins"], plan["pin_heights_mm"]))
        sets = format_arcs([(s["start"], s["width"]) for s in plan["final_sets"]])
        p.append(f"<tr><td>tight</td><td>{t['friction']}</td><td>{html.escape(pins)}</td>"
                 f"<td>{plan['n_final_sets']}</td><td>{sets}</td>"
                 f"<td>{_counts(checks.get('tight, mu_c ' + t['friction']))}</td></tr>")
    p.append("</table>")
    return p


def _sets(sets) -> str:
    return ", ".join(f"[{s['start']:.0f}, {s['start'] + s['width']:.0f}]" for s in sets)


def _sensing_section(res: dict, figs: dict, base) -> list[str]:
    """Force/torque sensor on the first pin: the verdict table and the two figures."""
    p = ["<h3>Force/torque sensor on the first pin</h3>"]
    if not res.get("found"):
        return p + ["<p>No allowed plan within the depth: no sensor plan.</p>"]
    t = res["score_table"]
    known = ("a known final orientation for every initial state" if res["known_for_every_state"]
             else f"up to {res['worst_sets']} final orientation sets for one verdict")
    p.append(f"<p>Sensor on {html.escape(res['first_pin'])} (y = {res['y_pin']:g} mm), plan "
             f"{html.escape(' → '.join(res['plan']['pins']))}: {known}. Classification accuracy "
             f"{100 * t['accuracy']:.0f} % (wrong {100 * t['wrong']:.0f} %) over {t['trials']} synthetic "
             f"measurements per state; fixed pins alone: {res['static_best']['n_final_sets']} sets "
             f"({html.escape(' → '.join(res['static_best']['pins']))}).</p>")
    p.append("<table><tr><th>sensor verdict (states it cannot tell apart)</th>"
             "<th>final orientation set(s) (deg)</th><th>known</th></tr>")
    for g in res["groups"]:
        p.append(f"<tr><td>{html.escape(', '.join(g['states']))}</td><td>{_sets(g['final_sets'])}</td>"
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
    for kind, alt in (("profiles", "force/torque profiles"), ("scores", "score table")):
        if kind in figs:
            p.append(f'<img src="{_rel(figs[kind], base)}" alt="{alt}">')
    return p
