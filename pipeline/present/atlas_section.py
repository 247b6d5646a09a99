"""The report's opening section: the feedability atlas as a grid of part
thumbnails (the outline figures), each framed in the colour of its outcome,
labelled with its pins, verified width and throughput, and linking to the
part's own section of the page."""
from __future__ import annotations

import html
import os

COLOURS = {"fixed pins": "#2a7d2a", "no pin needed": "#2a7d2a", "moving pins": "#c77c00",
           "sensor": "#b00", "no plan": "#b00"}
LEGEND = {"fixed pins": "fixed pins orient it", "no pin needed": "", "moving pins": "needs moving pins",
          "sensor": "no pin plan orients it (sensor)", "no plan": "no verified plan"}


def _label(row: dict) -> str:
    if row["outcome"] == "no pin needed":
        return f"no pin needed, {row['verified_width_deg']:.1f} deg"
    if row["plan"] is None:
        return "no verified plan"
    n = row["fixed_pins"] + row["moving_pins"]
    pins = f"{row['fixed_pins']} fixed" + (f" + {row['moving_pins']} moving" if row["moving_pins"] else "")
    pins += " pin" if n == 1 else " pins"
    if row["orients"]:
        how = "" if row["verified_width_deg"] is None else f", {row['verified_width_deg']:.1f} deg"
        if row.get("share_lower_bound") is not None:
            how += f" (>= {100 * row['share_lower_bound']:.1f} % in one set)"
    else:
        how = f": {row.get('sets')} sets of at most {row['tolerance_deg']:g} deg (sensor)"
    rate = "" if row.get("throughput_per_min") is None else f", {row['throughput_per_min']:.0f}/min"
    return f"{pins}{how}{rate}"


def atlas_section(atlas: dict, thumbnails: dict, base, anchor) -> list[str]:
    """HTML lines of the atlas grid. ``thumbnails``: part name -> image path;
    ``base``: the page's folder; ``anchor(name)``: a part section's anchor."""
    tol = atlas.get("tolerance_deg")
    p = ['<h2 id="atlas">Feedability atlas</h2>',
         f"<p>Which parts pins orient within {tol:g} deg (with {100 * (atlas.get('confidence') or 0.95):g} % confidence, at least "
         f"{100 * (atlas.get('required') or 0.995):g} % of the trials in one set, judged on held-out "
         f"trials; depth {atlas.get('depth')}), with how many pins, how "
         "precisely (verified width) and how fast (throughput at the layout's belt speed). "
         "Frame colour: " + ", ".join(f'<span style="color:{c}">{html.escape(LEGEND[k])}</span>'
                                      for k, c in COLOURS.items() if LEGEND[k] and k != "no plan") + ".</p>",
         '<div style="display:grid;grid-template-columns:repeat(auto-fill,minmax(150px,1fr));gap:8px">']
    for row in atlas["rows"]:
        name = row["part"]
        colour = COLOURS[row["outcome"]]
        img = thumbnails.get(name)
        pic = (f'<img src="{html.escape(os.path.relpath(img, base))}" alt="{html.escape(name)}" '
               f'style="width:100%">' if img else "")
        p.append(f'<a href="#{anchor(name)}" style="border:4px solid {colour};padding:4px;'
                 f'text-decoration:none;color:inherit;font-size:80%">{pic}'
                 f'<div><b>{html.escape(name)}</b><br>{html.escape(_label(row))}</div></a>')
    p.append("</div>")
    return p
