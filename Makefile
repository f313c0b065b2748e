PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: reproduce test bench benchmark lint docs clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(STAMP): $(BIN)/python pyproject.toml
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

reproduce: $(STAMP)
	$(BIN)/motionhyst reproduce --out out

lint: $(STAMP)
	$(BIN)/ruff check .

test: lint
	$(BIN)/python -m pytest

DOCS_STAMP := $(VENV)/.installed-docs

$(DOCS_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[test,docs]'
	touch $(DOCS_STAMP)

# the documentation site, warnings as errors, into docs/_build/html; then every link inside
# the site checked (page and anchor; links out of it are counted, not fetched: no network)
docs: $(DOCS_STAMP)
	$(BIN)/python -m sphinx -W --keep-going -q -b html docs docs/_build/html
	$(BIN)/python docs/checklinks.py docs/_build/html

bench: $(STAMP)
	$(BIN)/python benchmarks/run.py
	$(BIN)/python benchmarks/models.py
	$(BIN)/python benchmarks/speed.py
	$(BIN)/python benchmarks/scan.py
	$(BIN)/python benchmarks/scan_production.py
	$(BIN)/python benchmarks/sampled.py
	$(BIN)/python benchmarks/study.py
	$(BIN)/python benchmarks/study_memory.py
	$(BIN)/python benchmarks/predict_memory.py
	$(BIN)/python benchmarks/engine.py
	$(BIN)/python benchmarks/stability.py
	$(BIN)/python benchmarks/periodic.py
	$(BIN)/python benchmarks/point.py
	$(BIN)/python benchmarks/refusals.py
	$(BIN)/python benchmarks/one_stage.py
	$(BIN)/python benchmarks/axis_search.py

# the public benchmarks end to end (kept out of make test): Bouc-Wen (about a minute) and
# EMPS (a few minutes; scored on DATA_EMPS_PULSES.mat when EMPS_DATA holds it)
BENCHMARK_DATA ?= ../shared/benchmarks/bouc-wen
EMPS_DATA ?= ../shared/benchmarks/emps
benchmark: $(STAMP)
	$(BIN)/motionhyst benchmark bouc-wen --data $(BENCHMARK_DATA)
	$(BIN)/motionhyst benchmark emps --data $(EMPS_DATA)

clean:
	rm -rf $(VENV) out docs/_build docs/_generated docs/api docs/cli docs/examples
