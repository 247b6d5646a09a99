"""Checks on written images: read the file back and look at its pixels.

A byte count says little (an empty white figure of the right size, or a
stack trace saved as text, passes ``st_size > 1000``). These helpers decode
the file with matplotlib / Pillow and check what a reader would see: the
image's size, that something is drawn on the background, and, for a plot,
that it has axes (long straight dark lines: the spines).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _dark(rgb):
    """Pixels drawn in (near) black: spines, ticks, text."""
    return np.all(rgb < 0.35, axis=-1)


def _ink(rgb):
    """Pixels that differ from the background colour (the most common corner)."""
    corners = np.array([rgb[0, 0], rgb[0, -1], rgb[-1, 0], rgb[-1, -1]])
    values, counts = np.unique(np.round(corners, 3), axis=0, return_counts=True)
    background = values[np.argmax(counts)]
    return np.max(np.abs(rgb - background), axis=-1) > 0.1


def _longest_run(mask_1d) -> int:
    best = run = 0
    for v in mask_1d:
        run = run + 1 if v else 0
        best = max(best, run)
    return best


def assert_png_figure(path, min_width=300, min_height=150, min_ink=0.01, axes=True):
    """``path`` is a PNG of at least ``min_width`` x ``min_height`` pixels with at
    least ``min_ink`` of its pixels off the background; with ``axes``, a
    horizontal and a vertical dark line at least a tenth of the image long
    (a plot's spines; a tenth, so that one panel of a 4 x 4 grid counts) are
    drawn. Returns the image (rows, columns, channels)."""
    import matplotlib.image as mpimg
    path = Path(path)
    assert path.read_bytes()[:8] == PNG_SIGNATURE, f"{path} is not a PNG"
    img = mpimg.imread(path)
    assert img.ndim == 3 and img.shape[2] in (3, 4), img.shape
    h, w = img.shape[:2]
    assert w >= min_width and h >= min_height, f"{path}: {w} x {h} px"
    rgb = img[..., :3].astype(float)
    if img.shape[2] == 4:  # composite onto white, as a viewer shows it
        a = img[..., 3:4].astype(float)
        rgb = rgb * a + (1.0 - a)
    ink = _ink(rgb).mean()
    assert ink >= min_ink, f"{path}: blank ({100 * ink:.2f} % of pixels drawn)"
    if axes:
        dark = _dark(rgb)
        rows = max(_longest_run(r) for r in dark)
        cols = max(_longest_run(c) for c in dark.T)
        assert rows >= w / 10 and cols >= h / 10, (
            f"{path}: no axes (longest dark line {rows} px across, {cols} px down)")
    return img


def assert_animation(path, min_frames=2, min_width=200, min_height=100):
    """``path`` is an animated GIF of at least ``min_frames`` frames, each at
    least ``min_width`` x ``min_height``, not all the same, none blank."""
    from PIL import Image, ImageSequence
    with Image.open(path) as im:
        assert im.format == "GIF", f"{path} is {im.format}"
        frames = [np.asarray(f.convert("RGB"), dtype=float) / 255.0 for f in ImageSequence.Iterator(im)]
    assert len(frames) >= min_frames, f"{path}: {len(frames)} frames"
    h, w = frames[0].shape[:2]
    assert w >= min_width and h >= min_height, f"{path}: {w} x {h} px"
    for k, f in enumerate(frames):
        assert _ink(f).mean() >= 0.005, f"{path}: frame {k} is blank"
    assert any(not np.array_equal(frames[0], f) for f in frames[1:]), f"{path}: nothing moves"
    return frames
