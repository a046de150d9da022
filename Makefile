# Two entry points a new user needs: `make demo` (main job) and `make test`.
# Both create .venv with Python >= 3.12 (pyenv honours .python-version) on first use.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test lint bench pictures clean

$(STAMP): pyproject.toml
	$(PY) -c 'import sys; assert sys.version_info >= (3, 12), "GymFG-IL needs Python >= 3.12 (lerobot 0.6); install it or set PY=python3.12"'
	test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[dev]'
	touch $(STAMP)

demo: $(STAMP)
	HF_HUB_OFFLINE=1 $(BIN)/python -m gymfg_il.demo

test: $(STAMP)
	HF_HUB_OFFLINE=1 $(BIN)/python -m pytest -q

lint: $(STAMP)
	$(BIN)/ruff check gymfg_il tests benchmarks
	$(BIN)/mypy

bench: $(STAMP)
	$(BIN)/python -m benchmarks.run

# the README's and the docs' generated pictures, remade into docs/images/ from the current code
pictures: $(STAMP)
	PATH="$(CURDIR)/$(BIN):$$PATH" bash docs/experiments/pictures.sh

clean:
	rm -rf $(VENV) build *.egg-info
