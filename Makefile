# Quickstart: `make run` (set up .venv if needed, then the main job) and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: run support-study unlock demo test bench clean docs readme-figure

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test,cuda,docs]'
	touch $(STAMP)

# The main job: the Snakemake workflow on the embedded default config
# (config/config.yaml). Resumes an interrupted run; does nothing if up to date.
# Shows one line per finished stage; Snakemake's own output goes to
# logs/<config name>/snakemake-DATE-TIME.log (pipeline/workflow/console.py).
# Ends by printing the path of the report (results/<config name>/report.html;
# pipeline/workflow/runner.py prints it).
# After a killed run it removes Snakemake's stale lock and temporary files
# when no other run is alive (pipeline/workflow/runner.py), saying so in one line.
# First compiles the kernels once after an install or an edit of kernels/
# (pipeline/maps/warm.py; silent when they are cached), so that the jobs, and
# the first drawing planned after, load them instead.
run: $(STAMP)
	@$(BIN)/python -m pipeline.maps.warm
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/python -m pipeline.workflow run --cores all --rerun-incomplete

# The support-family study (rules/support.smk, config key support_study): not
# part of `make run` (about an hour of CPU on the default config; see
# docs/howto/support-family.md). Runs what it needs of `make run` first, then
# writes results/<config name>/report_support.html (the report with the study).
support-study: $(STAMP)
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/python -m pipeline.workflow run --cores all --rerun-incomplete support_study

# Remove Snakemake's lock by hand (only when no other run is alive).
unlock: $(STAMP)
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/snakemake --unlock

demo: $(STAMP)
	$(BIN)/pinfeed demo --out results/demo

# Two pytest-xdist workers (TEST_WORKERS=N for more, 0 for one process); tests
# sharing a costly fixture (the built manual, a module's workflow run) share one
# worker (tests/conftest.py).
TEST_WORKERS ?= 2
test: $(STAMP)
	$(BIN)/python -m pytest -q -n $(TEST_WORKERS) --dist loadgroup

bench: $(STAMP)
	$(BIN)/python benchmarks/rollout_speed.py

clean:
	rm -rf $(VENV) results .pytest_cache docs/_build docs/_generated docs/gallery docs/sg_execution_times.rst

# The manual: Sphinx, warnings as errors, into docs/_build/html.
docs: $(STAMP)
	PYTHONPATH=$(CURDIR) $(BIN)/python -m sphinx -b html -W --keep-going -q docs docs/_build/html

# The README's figure (docs/feeder_asym_triangle.png, committed: GitHub cannot
# run code) from the feeder drawing the docs build computed for this code
# (docs/_ext/default_run.py); tests/docs/test_front_page.py fails until it is
# refreshed after a change of the default plan.
readme-figure: $(STAMP)
	PYTHONPATH=$(CURDIR) $(BIN)/python docs/_ext/default_run.py
	cp docs/_generated/feeder_asym_triangle.png docs/feeder_asym_triangle.png
