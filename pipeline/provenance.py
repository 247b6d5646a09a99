"""What every stored file records about how it was made."""
from __future__ import annotations

import datetime as _dt
import functools
import os
import subprocess
from pathlib import Path

from . import __version__


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


def creation_time() -> str:
    """UTC time stamp; ``SOURCE_DATE_EPOCH`` pins it for bit-identical rebuilds."""
    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    when = (_dt.datetime.fromtimestamp(int(epoch), _dt.timezone.utc) if epoch
            else _dt.datetime.now(_dt.timezone.utc))
    return when.strftime("%Y-%m-%dT%H:%M:%SZ")


def provenance_attrs() -> dict:
    return {"pinfeed_version": __version__, "git_commit": git_commit(),
            "created": creation_time()}
