"""One-off: move the old README's sections into docs pages (kept for the record)."""
import re, sys
from pathlib import Path
root = Path(__file__).resolve().parents[2]
lines = (root / "README.md").read_text().splitlines()
def chunk(a, b):  # 1-based inclusive
    return lines[a - 1:b]
PAGES = {
 "reference/formats.md": ("File formats: catalog, shards, index, plans", [(41, 128), (210, 262)]),
 "explanation/bands-and-plans.md": ("Bands, plans, verification, report", [(129, 209), (507, 519)]),
 "explanation/complete.md": ("The complete search: \"complete\" and \"orients\"", [(263, 473)]),
 "howto/sweep-family.md": ("Sweep a family on a workstation", [(474, 506)]),
 "explanation/dynamic-pins.md": ("Dynamic pins", [(520, 564)]),
 "explanation/fast-belts.md": ("Fast belts: the dynamic model and the MuJoCo rig", [(565, 756)]),
 "howto/build-a-feeder.md": ("Build the feeder: layout drawings", [(757, 833)]),
 "howto/force-torque-sensor.md": ("Use a force/torque sensor", [(834, 971)]),
 "reference/cli-overview.md": ("Command line overview", [(972, 1017), (1184, 1191)]),
 "reference/errors.md": ("Bad input and faults: what you get", [(1018, 1058)]),
 "howto/cad-figures-animations.md": ("CAD outlines, figures, animations", [(1059, 1183)]),
 "reference/python-api-overview.md": ("Python API overview", [(1192, 1224)]),
 "reference/source-layout.md": ("Source layout", [(1225, 1343)]),
 "explanation/mechanics.md": ("Mechanics", [(1344, 1396)]),
 "explanation/supports.md": ("Support distributions", [(1397, 1632)]),
 "howto/fit-support.md": ("Fit a support to measured pushes", [(1633, 1692)]),
 "howto/support-family.md": ("Plan for a support family", [(1693, 1803)]),
 "development/testing.md": ("Tests and mutation checks", [(1804, 1967)]),
 "performance/index.md": ("Performance", [(1968, 2117)]),
}
ISSUE = {"25": "support families", "23": "the complete search", "18": "the belt-speed model",
         "11": "the sensor planner's rework", "15": "the speed work", "12": "the step budget"}
def clean(text, page):
    text = re.sub(r"\s*\((?:[Ii]ssue) \d+\)", "", text)
    text = re.sub(r";\s*issue \d+\)", ")", text)
    text = re.sub(r"\(issue 18; tested", "(tested", text)
    text = text.replace("Issue 25 adds", "Support families add")
    text = re.sub(r"issue (\d+)'s", lambda m: ISSUE[m.group(1)] + "'s", text)
    text = re.sub(r"issue (\d+)", lambda m: ISSUE[m.group(1)], text)
    depth = page.count("/")
    up = "../" * depth
    text = text.replace("](docs/spec-supports.md)", "](" + up + "explanation/spec-supports.md)")
    text = text.replace("](docs/", "](" + up)
    text = text.replace("](#mechanics-notes)", "](" + up + "explanation/mechanics.md)")
    text = text.replace("](#dynamic-pins)", "](" + up + "explanation/dynamic-pins.md)")
    return text
for page, (title, ranges) in PAGES.items():
    out = ["# " + title, "",
           "<!-- moved from the README; headings one level down -->", ""]
    for a, b in ranges:
        for ln in chunk(a, b):
            m = re.match(r"^(#+) (.*)$", ln)
            if m:
                level = len(m.group(1))
                ln = "#" * max(level, 2) + " " + m.group(2)
            out.append(ln)
        out.append("")
    p = root / "docs" / page
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(clean("\n".join(out).rstrip() + "\n", page))
    print(page, len(out))
