"""A workflow job's known error is one line in its log and on the console (issue 27)."""
import pytest

from pipeline.errors import PinfeedError
from pipeline.logs import log_to


def test_known_error_is_one_line_in_the_log_and_on_the_console(tmp_path, capsys):
    log = tmp_path / "logs" / "plan.log"
    with pytest.raises(SystemExit) as exc:
        with log_to(log):
            print("planning tri")
            raise PinfeedError("config error at planner/pins: give candidate heights")
    assert exc.value.code == 1
    line = "pinfeed: error: config error at planner/pins: give candidate heights\n"
    assert log.read_text() == "planning tri\n" + line
    assert capsys.readouterr().err == line


def test_other_errors_keep_their_traceback_in_the_log(tmp_path, capsys):
    log = tmp_path / "job.log"
    with pytest.raises(ZeroDivisionError):
        with log_to(log):
            1 / 0
    text = log.read_text()
    assert text.startswith("Traceback") and "ZeroDivisionError" in text
    assert capsys.readouterr().err == ""
