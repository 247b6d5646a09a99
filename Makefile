# Quickstart: `make run` (set up .venv if needed, then the main job) and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: run demo test bench clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

# The main job: the Snakemake workflow on the embedded default config
# (config/config.yaml). Resumes an interrupted run; does nothing if up to date.
# Ends by printing the path of the report (results/<config name>/report.html).
run: $(STAMP)
	PATH="$(CURDIR)/$(BIN):$$PATH" $(BIN)/snakemake --cores all --rerun-incomplete
	@$(BIN)/python -c 'from pipeline.config import load_config, results_folder; \
	print("report:", (results_folder(load_config()) / "report.html").resolve())'

demo: $(STAMP)
	$(BIN)/pinfeed demo --out results/demo

test: $(STAMP)
	$(BIN)/python -m pytest -q

bench: $(STAMP)
	$(BIN)/python benchmarks/rollout_speed.py

clean:
	rm -rf $(VENV) results .pytest_cache
