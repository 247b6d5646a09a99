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


FAIL_COLOUR = "#f8d0d0"


def plot_table(rows, title, out, header=HEADER) -> Path:
    """The rows as a table figure; rows with failures are shaded red."""
    fig, ax = plt.subplots(figsize=(11, 0.45 * (len(rows) + 2)))
    ax.axis("off")
    table = ax.table(cellText=rows or [["-"] * len(header)], colLabels=header, loc="center")
    table.auto_set_font_size(False)
    table.set_fontsize(8)
    table.auto_set_column_width(list(range(len(header))))
    fail_col = header.index("failures") if "failures" in header else None
    for r, row in enumerate(rows, start=1):
        if fail_col is not None and row[fail_col] not in ("0", "-"):
            for c in range(len(header)):
                table[r, c].set_facecolor(FAIL_COLOUR)
    ax.set_title(title, fontsize=10)
    return save_figure(fig, out, bbox_inches="tight")


SUCCESS_COLOUR = "tab:green"
REASON_COLOURS = ["tab:red", "tab:orange", "tab:purple", "tab:brown", "tab:pink", "tab:olive"]


def verification_figure(check: dict, title: str):
    """One plan's verification (a ``verify_plan`` result): a bar per initial
    state split into successes and failures by reason, ``successes/trials``
    written beside it, failing states' labels in red."""
    rows = check["rows"]
    reasons = sorted({k for r in rows for k in r["reasons"]})
    colours = dict(zip(reasons, REASON_COLOURS * (1 + len(reasons) // len(REASON_COLOURS))))
    fig, ax = plt.subplots(figsize=(7.5, 0.55 * len(rows) + 1.9))
    y = list(range(len(rows)))[::-1]
    ax.barh(y, [r["successes"] for r in rows], color=SUCCESS_COLOUR, label="success", height=0.6)
    left = [r["successes"] for r in rows]
    for reason in reasons:
        n = [r["reasons"].get(reason, 0) for r in rows]
        ax.barh(y, n, left=left, color=colours[reason], label=f"failure: {reason}", height=0.6)
        left = [a + b for a, b in zip(left, n)]
    most = max([r["trials"] for r in rows] + [1])
    for yy, r in zip(y, rows):
        ax.text(r["trials"] + 0.01 * most, yy, f"{r['successes']}/{r['trials']}", va="center", fontsize=8,
                color="tab:red" if r["failures"] else "black",
                fontweight="bold" if r["failures"] else "normal")
    ax.set_yticks(y, [r["state"] for r in rows], fontsize=8)
    for lbl, r in zip(ax.get_yticklabels(), rows):
        if r["failures"]:
            lbl.set_color("tab:red")
    ax.set_xlim(0, most * 1.15)
    ax.set_xlabel("perturbed trials", fontsize=8)
    ax.tick_params(labelsize=8)
    failed = sum(r["failures"] for r in rows)
    total = sum(r["trials"] for r in rows)
    verdict = f"{failed} of {total} trials failed" if failed else f"all {total} trials succeeded"
    ax.set_title(f"{title}\npins {' → '.join(check['plan'])}: {verdict}", fontsize=9,
                 color="tab:red" if failed else "black")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.35 if len(rows) < 3 else -0.2), ncol=2,
              fontsize=7, frameon=False)
    fig.tight_layout()
    return fig


def plot_verification(check: dict, title: str, out) -> Path:
    """Save :func:`verification_figure`."""
    return save_figure(verification_figure(check, title), out)
