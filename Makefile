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

# Two pytest workers (pytest-xdist), one per core of the 2-core CI machine, each taking whole test files
# (a module's fixtures are then built once); TEST_WORKERS=0 runs serially.
TEST_WORKERS ?= 2

test: $(VENV)/.dev
	$(PY) -m pytest -n $(TEST_WORKERS) --dist loadfile

test-all: $(VENV)/.dev
	$(PY) -m pytest -n $(TEST_WORKERS) --dist loadfile -m ''

bench: $(VENV)/.dev
	$(PY) tests/benchmarks/bench_risk.py

clean:
	rm -rf $(VENV) out build *.egg-info
