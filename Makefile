# uamopt: every target bootstraps its own virtual environment from pyproject.toml.
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
UAMOPT := $(VENV)/bin/uamopt

.PHONY: demo test test-all bench clean

$(VENV)/.base: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e .
	touch $@

$(VENV)/.dev: $(VENV)/.base
	$(PY) -m pip install --quiet -e '.[dev]'
	touch $@

demo: $(VENV)/.base
	$(UAMOPT) reproduce models/paper_case.toml --out out/paper_case

test: $(VENV)/.dev
	$(PY) -m pytest

test-all: $(VENV)/.dev
	$(PY) -m pytest -m ''

bench: $(VENV)/.dev
	$(PY) tests/benchmarks/bench_risk.py

clean:
	rm -rf $(VENV) out build *.egg-info
