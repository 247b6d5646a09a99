# PYTHON_ARGCOMPLETE_OK
"""The ``pinfeed`` command line: thin over ``pipeline`` modules.

Every error a user can cause prints one line ``pinfeed: error: ...`` on
stderr and exits with status 2; nothing already stored is touched.

One module per verb or group of verbs, each building its own parsers:

==============  =======================================================
module          verbs
==============  =======================================================
``maps``        ``rollout``, ``map``, ``plot-map``, ``demo``
``plans``       ``sweep``, ``plan``, ``atlas`` (``plan_text`` prints plans,
                ``next_steps`` what to run after one)
``catalog``     ``catalog index|list|show|query|plot``
``sense``       ``sense classify``
``support``     ``support fit``
``feeder``      ``speed``, ``layout``, ``animate``
``design``      ``design`` (the smallest outline change fixed pins orient)
``library``     ``library`` (every part of a folder of drawings, by the workflow)
``options``     the option groups they share
==============  =======================================================

:func:`build_parser` returns the whole parser (the manual's command reference
is generated from it; ``pinfeed --version`` prints ``pipeline.__version__``);
:func:`main` runs it, with shell completion by argcomplete when the shell asks.

Every command starts fast: building the parsers imports nothing heavy (no
numpy, planner, Numba kernels, xarray or matplotlib); each verb imports what
it uses inside the function that runs it. The environment (``SOURCE_DATE_EPOCH``,
``PINFEED_PROGRESS_SECONDS``) is checked before the verb runs, so a bad value
is one line, never a traceback from a library that read it first.
"""
from __future__ import annotations

import argparse
import re
import sys

from pipeline import __version__
from pipeline.cli import catalog, design, feeder, library, maps, plans, sense, support
from pipeline.cli.maps import DEFAULT_TRIANGLE, PAPER_D
from pipeline.cli.options import parse_values, progress_line
from pipeline.errors import PinfeedError
from pipeline.progress import progress_interval, reporting
from pipeline.provenance import source_date_epoch

__all__ = ["DEFAULT_TRIANGLE", "PAPER_D", "PinfeedParser", "build_parser", "main", "parse_values"]


class PinfeedParser(argparse.ArgumentParser):
    """argparse with the project's error contract: one line, exit status 2."""

    def error(self, message):
        """Print ``pinfeed: error: MESSAGE (see 'PROG --help')`` and exit with status 2."""
        self.exit(2, f"pinfeed: error: {message} (see '{self.prog} --help')\n")


# Options whose values may start with '-' (negative numbers, ranges such as
# -0.9:0.9:0.1) that argparse would otherwise take for an option.
SIGNED_VALUE_OPTIONS = {"--d", "--theta-i", "--pins", "--v-pin", "--speeds", "--y-pin"}


def join_signed_values(argv):
    """``argv`` with each signed-value option joined to a value that starts with '-'
    (``--d -0.5`` -> ``--d=-0.5``), so that argparse does not take the value for an option."""
    out, i = [], 0
    while i < len(argv):
        tok = argv[i]
        if tok in SIGNED_VALUE_OPTIONS and i + 1 < len(argv) and re.match(r"^-[\d.]", argv[i + 1]):
            out.append(f"{tok}={argv[i + 1]}")
            i += 2
        else:
            out.append(tok)
            i += 1
    return out


def build_parser() -> argparse.ArgumentParser:
    """The ``pinfeed`` argument parser, one subcommand per command."""
    parser = PinfeedParser(prog="pinfeed", description="pinfeed: design part feeders that orient flat parts "
                           "on a conveyor with overhead pins.")
    parser.add_argument("--version", action="version", version=f"pinfeed {__version__}",
                        help="print the version of pinfeed and exit")
    sub = parser.add_subparsers(dest="command", required=True)
    maps.add_map_commands(sub)
    plans.add_sweep_plan_commands(sub)
    catalog.add_catalog_commands(sub)
    sense.add_sense_commands(sub)
    support.add_support_commands(sub)
    feeder.add_stored_plan_commands(sub)
    feeder.add_layout_commands(sub)
    design.add_design_command(sub)
    library.add_library_command(sub)
    maps.add_demo_command(sub)
    sub.choices["plan"].set_defaults(func=_plan)
    return parser


def _print_plan_result(*args, **kwargs):
    """:func:`pipeline.cli.plan_text.print_plan_result`, imported when a plan is printed."""
    from pipeline.cli.plan_text import print_plan_result
    return print_plan_result(*args, **kwargs)


def _plan(args):
    """``pinfeed plan``, printing through this package's ``_print_plan_result``
    (looked up when called, so that a test may replace it)."""
    plans.cmd_plan(args, print_result=_print_plan_result)


def check_environment() -> None:
    """Refuse a bad ``SOURCE_DATE_EPOCH`` or ``PINFEED_PROGRESS_SECONDS`` with a
    :class:`PinfeedError` that says how to fix it; called before any verb
    imports numpy (whose f2py crashes on a non-numeric ``SOURCE_DATE_EPOCH``)."""
    source_date_epoch()
    progress_interval()


def _complete(parser) -> None:
    """Shell completion: answers the shell and exits when it asks (argcomplete's
    ``_ARGCOMPLETE`` variable is set); does nothing otherwise."""
    try:
        import argcomplete
    except ImportError:  # completion is a convenience: the command works without it
        return
    argcomplete.autocomplete(parser)


def main(argv=None) -> int:
    """Run the ``pinfeed`` command; returns the exit status.

    Parameters
    ----------
    argv : the arguments after the program name (default ``sys.argv[1:]``).
    """
    parser = build_parser()
    _complete(parser)
    args = parser.parse_args(join_signed_values(sys.argv[1:] if argv is None else list(argv)))
    try:
        check_environment()  # before any heavy import reads it, and before any work
        with reporting(progress_line):  # long stages say how far they have got, on stderr
            args.func(args)
    except PinfeedError as exc:
        print(f"pinfeed: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. piped into head
        return 0
    except KeyboardInterrupt:  # Ctrl-C: one line; writes are atomic, finished work is kept
        return _interrupted()
    except SystemError as exc:  # Ctrl-C inside a Numba kernel call arrives wrapped
        if not _caused_by_interrupt(exc):
            raise
        return _interrupted()
    return 0


def _interrupted() -> int:
    """Ctrl-C: one line on stderr and the shell's status 130 (128 + SIGINT)."""
    print("pinfeed: interrupted; finished files and the rollouts computed so far are kept "
          "(the next run reuses them)", file=sys.stderr)
    return 130


def _caused_by_interrupt(exc: BaseException) -> bool:
    """Whether ``exc`` was raised because of a KeyboardInterrupt (its cause chain)."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False
