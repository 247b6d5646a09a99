"""Progress for long work: a tqdm bar on a terminal, plain lines in logs.

On a TTY the bar redraws in place; elsewhere (Snakemake logs, pipes) a bar
would fill the log with carriage returns, so one line is printed when the
stage starts, at every tenth of the way, and when it ends.
"""
from __future__ import annotations

import sys
import time


def progress(items, total: int, desc: str, unit: str = "item", enabled: bool = True, stream=None):
    """Iterate ``items`` (``total`` of them) showing progress on ``stream`` (stderr)."""
    stream = stream or sys.stderr
    if not enabled or total == 0:
        yield from items
        return
    if getattr(stream, "isatty", lambda: False)():
        from tqdm import tqdm
        yield from tqdm(items, total=total, desc=desc, unit=unit, file=stream)
        return
    start = time.monotonic()
    print(f"{desc}: {total} {unit}s to do", file=stream, flush=True)
    step = max(1, total // 10)
    for k, item in enumerate(items, start=1):
        yield item
        if k % step == 0 or k == total:
            print(f"{desc}: {k}/{total} {unit}s done ({100 * k // total}%, "
                  f"{time.monotonic() - start:.0f} s)", file=stream, flush=True)
