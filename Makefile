# What a new user needs: `make demo` (the main job) and `make test` (the fast tests).
# Both create .venv with Python >= 3.12 (pyenv honours .python-version) on first use; the demo
# installs the runtime alone, the tests the development extras too.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
RUNTIME := $(VENV)/.runtime
STAMP := $(VENV)/.installed
PYTEST := HF_HUB_OFFLINE=1 $(BIN)/python -m pytest

.PHONY: demo test test-all lint bench docs pictures clean

$(VENV)/.python:
	$(PY) -c 'import sys; assert sys.version_info >= (3, 12), "GymFG-IL needs Python >= 3.12 (lerobot 0.6); install it or set PY=python3.12"'
	test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	touch $@

$(RUNTIME): pyproject.toml $(VENV)/.python
	$(BIN)/python -m pip install -q -e .
	touch $@

$(STAMP): pyproject.toml $(VENV)/.python
	$(BIN)/python -m pip install -q -e '.[dev]'
	touch $(RUNTIME) $@

demo: $(RUNTIME)
	HF_HUB_OFFLINE=1 $(BIN)/python -m gymfg_il.demo

# the fast run (under 5 minutes on 2 cores): everything but the tests marked slow or needing
# a real window, FlightGear, Ray, Node or LeRobot's own CLIs
test: $(STAMP)
	$(PYTEST) -q

# every test (what CI runs), with the slowest tests' durations
test-all: $(STAMP)
	$(PYTEST) -q -m "" --durations=25

lint: $(STAMP)
	$(BIN)/ruff check gymfg_il tests benchmarks
	$(BIN)/mypy

bench: $(STAMP)
	$(BIN)/python -m benchmarks.run

# the documentation site at http://127.0.0.1:8000, rebuilt as the docs change
docs: $(STAMP)
	$(BIN)/mkdocs serve

# the README's and the docs' generated pictures, remade into docs/images/ from the current code
pictures: $(STAMP)
	PATH="$(CURDIR)/$(BIN):$$PATH" bash docs/experiments/pictures.sh

clean:
	rm -rf $(VENV) build *.egg-info
