"""Result tables as figures and Markdown (the paper's Table 2)."""
from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt

from pipeline.present.figures import save_figure


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
    """A Markdown table of ``rows`` (lists of strings) under ``header``."""
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


def verification_figure(checks, title: str):
    """Verification of one or more plans (``verify_plan`` results, each optionally
    with a ``kind``): per plan, a bar per initial state split into successes and
    failures by reason, ``successes/trials`` beside it, failing states in red."""
    checks = [checks] if isinstance(checks, dict) else list(checks)
    reasons = sorted({k for c in checks for r in c["rows"] for k in r["reasons"]})
    colours = dict(zip(reasons, REASON_COLOURS * (1 + len(reasons) // len(REASON_COLOURS))))
    heights = [0.5 * len(c["rows"]) + 0.9 for c in checks]
    fig, axes = plt.subplots(len(checks), 1, figsize=(7.5, sum(heights) + 0.6 + 0.25 * (len(reasons) + 1)),
                             squeeze=False, gridspec_kw={"height_ratios": heights})
    for ax, check in zip(axes[:, 0], checks):
        _verification_bars(ax, check, colours)
    handles = [plt.Rectangle((0, 0), 1, 1, color=SUCCESS_COLOUR, label="success")]
    handles += [plt.Rectangle((0, 0), 1, 1, color=colours[r], label=f"failure: {r}") for r in reasons]
    fig.legend(handles=handles, loc="lower center", ncol=min(3, len(handles)), fontsize=7, frameon=False)
    fig.suptitle(title, fontsize=10)
    rows = 1 + len(handles) // 3
    fig.tight_layout(rect=(0, (0.22 * rows + 0.05) / fig.get_size_inches()[1], 1, 1))
    return fig


def _verification_bars(ax, check: dict, colours: dict):
    rows = check["rows"]
    y = list(range(len(rows)))[::-1]
    left = [0] * len(rows)
    for name, colour, counts in [("success", SUCCESS_COLOUR, [r["successes"] for r in rows])] + [
            (reason, colours[reason], [r["reasons"].get(reason, 0) for r in rows]) for reason in colours]:
        ax.barh(y, counts, left=left, color=colour, height=0.6)
        left = [a + b for a, b in zip(left, counts)]
    most = max([r["trials"] for r in rows] + [1])
    for yy, r in zip(y, rows):
        bad = r["failures"] > 0
        ax.text(r["trials"] + 0.01 * most, yy, f"{r['successes']}/{r['trials']}", va="center", fontsize=8,
                color="tab:red" if bad else "black", fontweight="bold" if bad else "normal")
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
    kind = f"{check['kind']}: " if check.get("kind") else ""
    ax.set_title(f"{kind}pins {' → '.join(check['plan'])}: {verdict}", fontsize=9,
                 color="tab:red" if failed else "black")


def plot_verification(checks, title: str, out) -> Path:
    """Save :func:`verification_figure`."""
    return save_figure(verification_figure(checks, title), out)
