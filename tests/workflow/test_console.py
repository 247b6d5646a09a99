"""What ``make run`` shows on the terminal (pipeline/workflow/console.py): one
line per finished stage read from Snakemake's output, a closing line, and for
a failed job its rule, log path and the log's last lines; few lines in all.

SMALL_RUN is Snakemake 9.27's output for ``make run`` on the paper-feeder
tutorial's small config (tests/data/paper_feeder_small.yaml, 2 cores, under
load), recorded 2026-11-26 with the job listings' input/output/reason lines
and the header's machine lines left out (the reader skips them anyway).
FAILED_RUN is its output for a two-rule Snakefile whose second rule fails
(the same Snakefile :func:`test_a_real_failure_shows_rule_log_and_error`
runs)."""
from __future__ import annotations

import io
import re
import sys
from datetime import datetime

from pipeline.workflow import runner
from pipeline.workflow.console import Progress, Terminal, clock, follow

SMALL_RUN = """\
Assuming unrestricted shared filesystem usage.

SNAKEMAKE
=========
  Date: 2026-11-26 10:04:40
  Snakemake version: 9.27.1

Building DAG of jobs...
Using shell: /usr/bin/bash
Provided cores: 2
Rules claiming more threads will be scaled down.
Conda environments: ignored
Job stats:
job                count
---------------  -------
sweep_shard            2
bands                  2
catalog_index          1
plan                   1
layout                 1
outline                1
sense                  1
speed                  1
verify                 1
animate                1
atlas                  1
figures                1
sensing_figures        1
report                 1
all                    1
total                 17

Select jobs to execute...
Execute 2 jobs...

[Thu Nov 26 10:05:03 2026]
localrule sweep_shard:
    log: logs/sweep/paper_triangles/asym_triangle-e6ce061196/minpower/mu_c=0.15.log
    jobid: 2
[Thu Nov 26 10:05:03 2026]
localrule sweep_shard:
    log: logs/sweep/paper_triangles/sym_triangle-1264dca961/minpower/mu_c=0.15.log
    jobid: 3
[Thu Nov 26 10:05:26 2026]
Finished jobid: 2 (Rule: sweep_shard)
1 of 17 steps (6%) done
Select jobs to execute...
Execute 1 jobs...

[Thu Nov 26 10:05:26 2026]
localrule bands:
    log: logs/config/bands/paper_triangles/asym_triangle-e6ce061196/minpower/mu_c=0.15.log
    jobid: 4
Select jobs to execute...
[Thu Nov 26 10:05:29 2026]
Finished jobid: 3 (Rule: sweep_shard)
2 of 17 steps (12%) done
Execute 1 jobs...

[Thu Nov 26 10:05:29 2026]
localrule catalog_index:
    log: logs/catalog/index.log
    jobid: 1
Select jobs to execute...
[Thu Nov 26 10:05:43 2026]
Finished jobid: 1 (Rule: catalog_index)
3 of 17 steps (18%) done
Execute 1 jobs...

[Thu Nov 26 10:05:43 2026]
localrule bands:
    log: logs/config/bands/paper_triangles/sym_triangle-1264dca961/minpower/mu_c=0.15.log
    jobid: 5
Select jobs to execute...
[Thu Nov 26 10:05:56 2026]
Finished jobid: 4 (Rule: bands)
4 of 17 steps (24%) done
Execute 1 jobs...

[Thu Nov 26 10:05:56 2026]
localrule plan:
    log: logs/config/plan/asym_triangle.log
    jobid: 7
[Thu Nov 26 10:06:16 2026]
Finished jobid: 5 (Rule: bands)
5 of 17 steps (29%) done
[Thu Nov 26 10:06:39 2026]
Finished jobid: 7 (Rule: plan)
6 of 17 steps (35%) done
Select jobs to execute...
Execute 2 jobs...

[Thu Nov 26 10:06:40 2026]
localrule speed:
    log: logs/config/speed/asym_triangle.log
    jobid: 8
[Thu Nov 26 10:06:40 2026]
localrule layout:
    log: logs/config/layout/asym_triangle.log
    jobid: 9
Select jobs to execute...
[Thu Nov 26 10:07:05 2026]
Finished jobid: 8 (Rule: speed)
7 of 17 steps (41%) done
Execute 1 jobs...

[Thu Nov 26 10:07:05 2026]
localrule sense:
    log: logs/config/sense/asym_triangle.log
    jobid: 15
Select jobs to execute...
[Thu Nov 26 10:07:47 2026]
Finished jobid: 9 (Rule: layout)
8 of 17 steps (47%) done
Execute 1 jobs...

[Thu Nov 26 10:07:47 2026]
localrule animate:
    log: logs/config/animate/asym_triangle.log
    jobid: 14
Select jobs to execute...
[Thu Nov 26 10:07:52 2026]
Finished jobid: 15 (Rule: sense)
9 of 17 steps (53%) done
Execute 1 jobs...

[Thu Nov 26 10:07:52 2026]
localrule atlas:
    log: logs/config/atlas.log
    jobid: 6
Select jobs to execute...
[Thu Nov 26 10:08:06 2026]
Finished jobid: 6 (Rule: atlas)
10 of 17 steps (59%) done
Execute 1 jobs...

[Thu Nov 26 10:08:06 2026]
localrule verify:
    log: logs/config/verify/asym_triangle.log
    jobid: 12
Select jobs to execute...
[Thu Nov 26 10:08:38 2026]
Finished jobid: 12 (Rule: verify)
11 of 17 steps (65%) done
Execute 1 jobs...

[Thu Nov 26 10:08:39 2026]
localrule figures:
    log: logs/config/figures.log
    jobid: 11
Select jobs to execute...
[Thu Nov 26 10:08:48 2026]
Finished jobid: 14 (Rule: animate)
12 of 17 steps (71%) done
Execute 1 jobs...

[Thu Nov 26 10:08:48 2026]
localrule sensing_figures:
    log: logs/config/sense/figures_asym_triangle.log
    jobid: 16
Select jobs to execute...
[Thu Nov 26 10:09:39 2026]
Finished jobid: 16 (Rule: sensing_figures)
13 of 17 steps (76%) done
Execute 1 jobs...

[Thu Nov 26 10:09:39 2026]
localrule outline:
    log: logs/config/outline/asym_triangle.log
    jobid: 13
[Thu Nov 26 10:09:59 2026]
Finished jobid: 11 (Rule: figures)
14 of 17 steps (82%) done
[Thu Nov 26 10:10:17 2026]
Finished jobid: 13 (Rule: outline)
15 of 17 steps (88%) done
Select jobs to execute...
Execute 1 jobs...

[Thu Nov 26 10:10:17 2026]
localrule report:
    log: logs/config/report.log
    jobid: 10
[Thu Nov 26 10:10:47 2026]
Finished jobid: 10 (Rule: report)
16 of 17 steps (94%) done
Select jobs to execute...
Execute 1 jobs...

[Thu Nov 26 10:10:47 2026]
localrule all:
    jobid: 0
[Thu Nov 26 10:10:47 2026]
Finished jobid: 0 (Rule: all)
17 of 17 steps (100%) done
Complete log(s): /tmp/pf_small/.snakemake/log/2026-11-26T100440.259514.snakemake.log
Elapsed time: 0:06:07.676873
"""

FAILING_SNAKEFILE = """\
rule all:
    input: "b.txt"
rule a:
    output: "a.txt"
    shell: "echo hi > {output}"
rule b:
    input: "a.txt"
    output: "b.txt"
    log: "logs/b.log"
    shell: "echo 'Traceback (most recent call last):' > {log}; echo 'ValueError: bad pin' >> {log}; exit 3"
"""

FAILED_RUN = """\
Building DAG of jobs...
Using shell: /usr/bin/bash
Provided cores: 1 (use --cores to define parallelism)
Rules claiming more threads will be scaled down.
Job stats:
job      count
-----  -------
a            1
b            1
all          1
total        3

Select jobs to execute...
Execute 1 jobs...

[Thu Nov 26 10:02:40 2026]
localrule a:
    output: a.txt
    jobid: 2
    reason: Missing output files: a.txt
    resources: tmpdir=/tmp
[Thu Nov 26 10:02:40 2026]
Finished jobid: 2 (Rule: a)
1 of 3 steps (33%) done
Select jobs to execute...
Execute 1 jobs...

[Thu Nov 26 10:02:40 2026]
localrule b:
    input: a.txt
    output: b.txt
    log: logs/b.log
    jobid: 1
    reason: Missing output files: b.txt; Input files updated by another job: a.txt
    resources: tmpdir=/tmp
RuleException:
CalledProcessError in file "/tmp/sm_fail/Snakefile", line 10:
Command 'set -euo pipefail;  echo 'Traceback' > logs/b.log; exit 3' returned non-zero exit status 3.
[Thu Nov 26 10:02:41 2026]
Error in rule b:
    message: None
    jobid: 1
    input: a.txt
    output: b.txt
    log: logs/b.log (check log file(s) for error details)
    shell:
        echo 'Traceback' > logs/b.log; exit 3
        (command exited with non-zero exit code)
Shutting down, this might take some time.
Exiting because a job execution failed. Look above for error messages
Complete log(s): /tmp/sm_fail/.snakemake/log/2026-11-26T100239.811688.snakemake.log
Elapsed time: 0:00:01.083429
WorkflowError:
At least one job did not complete successfully.
"""


def replay(text, **kw):
    progress = Progress(**kw)
    lines = [t for line in text.splitlines() for t in progress.feed(line)]
    return progress, lines


def test_clock():
    assert clock(0) == " 0:00" and clock(192.4) == " 3:12" and clock(3725) == "1:02:05"


def test_one_line_per_finished_stage_with_counts_and_times():
    progress, lines = replay(SMALL_RUN)
    assert lines[0] == "pinfeed: 17 jobs to run on 2 cores"
    stages = [line.split()[2] for line in lines[1:]]
    # every rule once, in the order its last job finished; no line for the target rule all
    assert stages == ["sweep_shard", "catalog_index", "bands", "plan", "speed", "layout", "sense", "atlas",
                      "verify", "animate", "sensing_figures", "figures", "outline", "report"]
    # elapsed from Snakemake's start (Date: 10:04:40) to the stage's last job; the
    # stage's own time from its first job's start
    assert lines[1] == "[ 0:49] sweep_shard          2/2  map shards                  0:26"
    assert lines[3] == "[ 1:36] bands                2/2  bands of every map          0:50"
    assert lines[-1] == "[ 6:07] report               1/1  report                      0:30"
    assert progress.steps == (17, 17) and not progress.failures
    assert progress.summary(0, 367.7, "logs/x.log") == ["[ 6:08] done: 17 of 17 jobs in 6:08"]


def test_the_live_line_names_what_runs():
    progress, _ = replay(SMALL_RUN.split("Finished jobid: 7 (Rule: plan)")[0])
    assert progress.status(83) == "[ 1:23] 5/17 jobs; running: plan 0/1"
    assert Progress().status(2) == "[ 0:02] Snakemake is building its job graph"


def test_a_default_run_fits_on_a_screen():
    """The default config's 141 jobs: one line per stage (14), the opening
    and closing lines and the report's path stay under 40 lines."""
    totals = {"sweep_shard": 60, "bands": 60, "catalog_index": 1, "plan": 2, "layout": 2, "outline": 2,
              "sense": 2, "speed": 2, "verify": 2, "animate": 2, "atlas": 1, "figures": 1,
              "sensing_figures": 2, "report": 1, "all": 1}
    text = ["Provided cores: 2", "Job stats:", "job  count", "---  -----",
            *(f"{r}  {n}" for r, n in totals.items()), f"total  {sum(totals.values())}"]
    step, jobid = 0, 0
    for rule, n in totals.items():
        for _ in range(n):
            jobid += 1
            step += 1
            text += ["[Thu Nov 26 10:00:20 2026]", f"localrule {rule}:", "    log: x.log", f"    jobid: {jobid}",
                     "[Thu Nov 26 10:01:20 2026]", f"Finished jobid: {jobid} (Rule: {rule})",
                     f"{step} of 141 steps ({100 * step // 141}%) done"]
    progress, lines = replay("\n".join(text), start=datetime(2026, 11, 26, 10, 0, 10))
    lines += progress.summary(0, 410, "logs/config/snakemake.log")
    assert len(lines) == 16 and len(lines) + 2 <= 40  # + the log's path and the report's
    assert lines[-1] == "[ 6:50] done: 141 of 141 jobs in 6:50"


def test_a_failure_shows_rule_log_and_the_logs_last_lines(tmp_path):
    (tmp_path / "logs").mkdir()
    (tmp_path / "logs" / "b.log").write_text("planning tri\n" + "".join(f"step {k}\n" for k in range(30))
                                             + "Traceback (most recent call last):\nValueError: bad pin\n")
    progress, lines = replay(FAILED_RUN, workdir=tmp_path)
    lines += progress.summary(1, 2.0, "logs/config/snakemake-1.log")
    assert lines[0] == "pinfeed: 3 jobs to run on 1 core"
    assert lines[1] == "[ 0:00] a                    1/1                              0:00"
    assert lines[2] == "[ 0:01] FAILED: rule b (jobid 1)" and lines[3] == "  log: logs/b.log"
    shown = [t.removeprefix("  | ") for t in lines[4:-1]]
    assert shown[-2:] == ["Traceback (most recent call last):", "ValueError: bad pin"] and len(shown) == 12
    assert lines[-1] == ("pinfeed: the workflow failed after 0:02 (1 of 3 jobs done); Snakemake's full "
                         "log: logs/config/snakemake-1.log")


def test_a_failure_without_a_log_shows_snakemakes_last_lines(tmp_path):
    progress, lines = replay(FAILED_RUN, workdir=tmp_path)  # logs/b.log is not there
    text = "\n".join(lines + progress.summary(1, 2.0, "x.log"))
    assert "FAILED: rule b" in text and "log: logs/b.log" in text
    assert "| CalledProcessError in file" in text and "returned non-zero exit status 3" in text
    assert "Shutting down" not in text and "Complete log" not in text


def test_snakemakes_banner_is_not_among_the_last_lines():
    banner = ("Assuming unrestricted shared filesystem usage.\n\nSNAKEMAKE\n=========\n"
              "  Date: 2026-11-26 10:04:40\n  Snakemake version: 9.27.1\n  Command: snakemake x\n\n"
              "Building DAG of jobs...\nWorkflowError:\nTarget rules may not contain wildcards.\n")
    progress, lines = replay(banner)
    assert progress.start == datetime(2026, 11, 26, 10, 4, 40)
    assert progress.tail == ["Target rules may not contain wildcards."]


def test_an_error_before_any_job_shows_snakemakes_last_lines():
    progress, lines = replay("Building DAG of jobs...\nPinfeedError in file /w/Snakefile, line 32:\n"
                             "config error at planner/depth: 0 is less than the minimum of 1\n"
                             "  File \"/w/Snakefile\", line 32, in <module>\n")
    out = progress.summary(1, 3.0, "x.log")
    assert out[0] == "Snakemake's last lines:"
    assert "  | config error at planner/depth: 0 is less than the minimum of 1" in out
    assert out[-1].startswith("pinfeed: the workflow failed after 0:03 (0 of 0 jobs done)")


def test_nothing_to_do_and_the_snakefiles_own_notes():
    progress, lines = replay("pinfeed: catalog/x.h5: expected by the config but missing\n"
                             "Building DAG of jobs...\nNothing to be done (all requested files are present "
                             "and up to date).\n")
    assert lines == ["pinfeed: catalog/x.h5: expected by the config but missing"]
    assert progress.summary(0, 4.0, "x.log") == ["[ 0:04] nothing to do: every result is up to date"]


def test_the_terminal_keeps_one_live_line():
    out = io.StringIO()
    term = Terminal(out, live=True)
    term.status("[ 0:01] 0/3 jobs")
    term.status("[ 0:01] 0/3 jobs")  # unchanged: not written again
    term.status("[ 0:02] 1/3 jobs")
    term.line("[ 0:02] a  1/1")
    assert out.getvalue() == "\r\x1b[K[ 0:01] 0/3 jobs\r\x1b[K[ 0:02] 1/3 jobs\r\x1b[K[ 0:02] a  1/1\n"
    quiet = io.StringIO()
    Terminal(quiet, live=False).status("x")
    assert quiet.getvalue() == ""


def test_a_real_failure_shows_rule_log_and_error(tmp_path):
    """A two-rule Snakefile whose second job fails, through :func:`follow` (about 3 s)."""
    (tmp_path / "Snakefile").write_text(FAILING_SNAKEFILE)
    out = io.StringIO()
    log = tmp_path / "logs" / "snakemake-1.log"
    code = follow([sys.executable, "-m", "snakemake", "-s", str(tmp_path / "Snakefile"), "--cores", "1",
                   "--directory", str(tmp_path)], log, Terminal(out, live=False), poll=0.05, workdir=tmp_path)
    lines = out.getvalue().splitlines()
    assert code != 0
    assert lines[0] == f"pinfeed: running Snakemake; its full log: {log}"
    # Rule a's line: done 1 of 1, and its duration (0:00, or 0:01 on a slow start).
    assert any(re.search(r"\] a {20}1/1 {30}0:0[01]$", t) for t in lines), lines
    failed = next(k for k, t in enumerate(lines) if "FAILED: rule b" in t)
    assert lines[failed + 1:failed + 4] == ["  log: logs/b.log", "  | Traceback (most recent call last):",
                                           "  | ValueError: bad pin"]
    assert lines[-1].startswith("pinfeed: the workflow failed after") and str(log) in lines[-1]
    assert len(lines) <= 10
    assert "Error in rule b:" in log.read_text()  # Snakemake's own output, whole, in the log


def test_dry_runs_and_listings_print_snakemakes_own_output():
    assert runner._passes_through(["--cores", "all", "-n"]) and runner._passes_through(["--list-rules"])
    assert not runner._passes_through(["--cores", "all", "--rerun-incomplete", "support_study"])


def test_snakemakes_log_is_named_by_config_and_date(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "small.yaml").write_text("name: mine\n")
    log = runner._snakemake_log(["--configfile", "small.yaml"])
    assert log.parent == __import__("pathlib").Path("logs/mine") and log.name.startswith("snakemake-")
    assert runner._snakemake_log([]).parent.as_posix() == "logs/config"
