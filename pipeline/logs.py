"""Send a rule script's output and tracebacks to its Snakemake log file."""
from __future__ import annotations

import contextlib
import sys
import traceback
from pathlib import Path

from pipeline.errors import PinfeedError
from pipeline.progress import reporting


@contextlib.contextmanager
def log_to(path):
    """Redirect stdout and stderr to the log file ``path`` for the block. A known
    error (:class:`PinfeedError`) is one line ``pinfeed: error: ...`` in the log
    and on the console, and the job exits with status 1; anything else is
    logged with its traceback and raised. Long stages write how far they have
    got into the log as well (:func:`pipeline.progress.reporting`)."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    console = sys.stderr
    with open(path, "w") as fh:
        try:
            with contextlib.redirect_stdout(fh), contextlib.redirect_stderr(fh), \
                    reporting(lambda line: print(line, file=fh, flush=True)):
                yield fh
        except PinfeedError as exc:
            for stream in (fh, console):
                print(f"pinfeed: error: {exc}", file=stream, flush=True)
            raise SystemExit(1) from None
        except BaseException:
            traceback.print_exc(file=fh)
            raise
