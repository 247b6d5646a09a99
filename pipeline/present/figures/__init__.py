"""Figures, one module per kind. All use the paper's conventions: theta_i on
the x axis, theta_f on the y axis, degrees."""
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt  # noqa: E402 (after choosing the backend)


def save_figure(fig, out, dpi=130, **kwargs) -> Path:
    """Write ``fig`` to ``out`` (making its folder) and free it."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=dpi, **kwargs)
    plt.close(fig)
    return out


def placeholder(path, text) -> Path:
    """A small figure at ``path`` that only says ``text`` (a result with nothing
    to draw: no plan, no speed limit, nothing verified)."""
    fig, ax = plt.subplots(figsize=(6, 1.5))
    ax.axis("off")
    ax.text(0.5, 0.5, text, ha="center", va="center")
    return save_figure(fig, path, dpi=100)


def placeholder_gif(path, text) -> Path:
    """A one-frame GIF at ``path`` saying ``text`` (a part with no plan to animate)."""
    from PIL import Image
    png = Path(path).with_name(Path(path).stem + ".note.png")
    placeholder(png, text)
    with Image.open(png) as im:
        im.convert("RGB").save(path, format="GIF")
    png.unlink()
    return Path(path)


def circle_axes(ax):
    """Both axes 0..360 degrees with ticks every 90: theta_i on x, theta_f on y."""
    ax.set_xlim(0, 360)
    ax.set_ylim(0, 360)
    ax.set_xticks([0, 90, 180, 270, 360])
    ax.set_yticks([0, 90, 180, 270, 360])
    ax.tick_params(labelsize=7)


LABEL_ROW_PT = 9.0  # one row of 7-point labels above an axes


def label_above(ax, x: float, text: str, **kwargs):
    """A label centred at data ``x`` just above ``ax`` (rows: :func:`stagger_labels`)."""
    return ax.annotate(text, xy=(x, 1.0), xycoords=ax.get_xaxis_transform(), xytext=(0.0, 2.0),
                       textcoords="offset points", ha="center", va="bottom", annotation_clip=False,
                       **kwargs)


def stagger_labels(fig, labels) -> int:
    """Raise each label of :func:`label_above` that would overlap an earlier one by
    whole rows of :data:`LABEL_ROW_PT` points until it overlaps none (close pins
    get stacked labels); returns the number of rows used, for a title's pad."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    placed, rows = [], 1
    for label in labels:
        row = 0
        while any(label.get_window_extent(renderer).overlaps(box) for box in placed):
            row += 1
            label.xyann = (0.0, 2.0 + LABEL_ROW_PT * row)
        placed.append(label.get_window_extent(renderer))
        rows = max(rows, row + 1)
    return rows


def text_problems(fig) -> list[str]:
    """Visible texts of ``fig`` that overlap one another or stick out of the
    figure, measured with the renderer (the figure as it would be saved)."""
    from matplotlib.text import Text
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    page = fig.bbox
    hidden = _undrawn_tick_labels(fig)
    texts = [t for t in fig.findobj(Text) if t.get_visible() and t.get_text().strip()
             and id(t) not in hidden]
    boxes = [(t, t.get_window_extent(renderer)) for t in texts]
    problems = []
    for t, b in boxes:
        clip = t.get_clip_box() if t.get_clip_on() else None
        for box in (page, clip):
            if box is not None and (b.x0 < box.x0 - 0.5 or b.y0 < box.y0 - 0.5
                                    or b.x1 > box.x1 + 0.5 or b.y1 > box.y1 + 0.5):
                problems.append(f"clipped: {t.get_text()!r}")
                break
    for i, (t, b) in enumerate(boxes):
        for u, c in boxes[i + 1:]:
            # Shrink by half a pixel so boxes that merely touch do not count.
            if b.x0 + 0.5 < c.x1 and c.x0 + 0.5 < b.x1 and b.y0 + 0.5 < c.y1 and c.y0 + 0.5 < b.y1:
                problems.append(f"overlap: {t.get_text()!r} and {u.get_text()!r}")
    return problems


def _undrawn_tick_labels(fig) -> set:
    """ids of tick labels matplotlib keeps but does not draw (ticks outside the view)."""
    out = set()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            lo, hi = sorted(axis.get_view_interval())
            eps = 1e-9 * max(1.0, abs(hi - lo))
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                if not lo - eps <= tick.get_loc() <= hi + eps:
                    out.update({id(tick.label1), id(tick.label2)})
    return out
