"""What every stored file records about how it was made."""
from __future__ import annotations

import datetime as _dt
import functools
import os
import subprocess
from pathlib import Path

from pipeline import __version__
from pipeline.errors import PinfeedError


@functools.lru_cache(maxsize=1)
def git_commit() -> str:
    """Commit of the source tree pinfeed runs from, ``+dirty`` if modified, or ``unknown``."""
    root = Path(__file__).resolve().parent.parent
    try:
        sha = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                             text=True, timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                               capture_output=True, text=True, timeout=10).stdout.strip()
        return sha + ("+dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def source_date_epoch() -> int | None:
    """``SOURCE_DATE_EPOCH`` as seconds, None if unset, or a clear error. Checked
    at start-up too (the CLI and config loading): numpy's f2py, which the kernels
    import, crashes on a non-numeric value before pinfeed would see it."""
    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    if not epoch:
        return None
    try:
        value = int(epoch)
        _dt.datetime.fromtimestamp(value, _dt.timezone.utc)
    except (ValueError, OverflowError, OSError):
        raise PinfeedError(f"SOURCE_DATE_EPOCH must be a whole number of seconds since 1970 "
                           f"(e.g. 1700000000), got {epoch!r}; fix or unset it") from None
    return value


def creation_time() -> str:
    """UTC time stamp; ``SOURCE_DATE_EPOCH`` pins it for bit-identical rebuilds."""
    epoch = source_date_epoch()
    when = (_dt.datetime.fromtimestamp(epoch, _dt.timezone.utc) if epoch is not None
            else _dt.datetime.now(_dt.timezone.utc))
    return when.strftime("%Y-%m-%dT%H:%M:%SZ")


def provenance_attrs() -> dict:
    """Version, git commit and creation time to store with a result."""
    return {"pinfeed_version": __version__, "git_commit": git_commit(),
            "created": creation_time()}
