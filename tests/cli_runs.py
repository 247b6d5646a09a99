"""Run the ``pinfeed`` CLI in-process for tests (imported by bare name)."""
from pipeline.cli import main


def run_cli(capsys, argv):
    """Run ``pinfeed argv`` in-process; return (exit code, stdout, stderr).

    argparse errors exit through ``SystemExit``; its code is returned."""
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err
