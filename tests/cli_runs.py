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


# A small own triangle planned from the command line (depth 1, three pins).
TRI_PLAN_ARGS = ["--vertices", "0,0 60,0 15,35", "--name", "tri", "--depth", "1", "--pins=7.5,27.5,42.5",
                 "--mu-c", "0", "--dynamic-depth", "0"]


def small_config_file(tmp_path):
    """The default config with few verification trials and candidates (fast),
    written as ``tmp_path/small.yaml``; returns its path."""
    import yaml

    from pipeline.config import load_config
    cfg = load_config(None)
    cfg["verify"]["trials"] = 20
    cfg["verify"]["rule"] = "point"  # 20 trials cannot carry a 99.5 % claim with confidence
    cfg["planner"]["candidates"] = 3
    cfg["speed"].update(trials=5, speeds=[50.0, 300.0], resolution=25.0)
    cfg.pop("name", None)
    path = tmp_path / "small.yaml"
    path.write_text(yaml.safe_dump(cfg))
    return path
