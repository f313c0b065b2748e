PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: reproduce test bench benchmark lint clean

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

bench: $(STAMP)
	$(BIN)/python benchmarks/run.py
	$(BIN)/python benchmarks/models.py

# the Bouc-Wen hysteretic benchmark end to end (about a minute; kept out of make test)
BENCHMARK_DATA ?= ../shared/benchmarks/bouc-wen
benchmark: $(STAMP)
	$(BIN)/motionhyst benchmark bouc-wen --data $(BENCHMARK_DATA)

clean:
	rm -rf $(VENV) out
