"""Send a rule script's output and tracebacks to its Snakemake log file."""
from __future__ import annotations

import contextlib
import traceback
from pathlib import Path


@contextlib.contextmanager
def log_to(path):
    """Redirect stdout and stderr to the log file ``path`` (tracebacks included) for the block."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as fh, contextlib.redirect_stdout(fh), contextlib.redirect_stderr(fh):
        try:
            yield fh
        except BaseException:
            traceback.print_exc(file=fh)
            raise
