"""Result tables as figures and Markdown (the paper's Table 2)."""
from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt

from . import save_figure


def verification_rows(results: dict) -> list[list[str]]:
    """Rows (part, plan, kind of pins, state, trials, successes, failures, reasons) from
    verify results by part (each with its ``checks``)."""
    rows = []
    for part, res in results.items():
        for check in res["checks"]:
            for r in check["rows"]:
                reasons = "; ".join(f"{k}: {v}" for k, v in sorted(r["reasons"].items())) or "n/a"
                rows.append([part, " ".join(check["plan"]), check["kind"], r["state"], str(r["trials"]),
                             str(r["successes"]), str(r["failures"]), reasons])
    return rows


HEADER = ["part", "plan", "pins", "initial state", "trials", "successes", "failures", "reason"]


def markdown_table(rows, header=HEADER) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def plot_table(rows, title, out, header=HEADER) -> Path:
    fig, ax = plt.subplots(figsize=(11, 0.45 * (len(rows) + 2)))
    ax.axis("off")
    table = ax.table(cellText=rows or [["-"] * len(header)], colLabels=header, loc="center")
    table.auto_set_font_size(False)
    table.set_fontsize(8)
    table.auto_set_column_width(list(range(len(header))))
    ax.set_title(title, fontsize=10)
    return save_figure(fig, out, bbox_inches="tight")
