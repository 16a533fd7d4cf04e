# uamopt: every target bootstraps its own virtual environment from pyproject.toml.
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
UAMOPT := $(VENV)/bin/uamopt
# Every install is pinned to the versions of constraints.txt (pip freeze of a working .venv).
CONSTRAINTS := constraints.txt
PIP     = $(PY) -m pip install --quiet -c $(CONSTRAINTS)
# The base venv: the core and the extras `uamopt reproduce` (make demo) needs: HiGHS and CP-SAT, the 3-D view.
BASE_EXTRAS ?= exact,view

.PHONY: demo lint test test-slow test-all bench notebooks notebooks-run clean

$(VENV)/.base: pyproject.toml $(CONSTRAINTS)
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PIP) -e '.[$(BASE_EXTRAS)]'
	touch $@

$(VENV)/.dev: $(VENV)/.base $(VENV)/.browser
	$(PIP) -e '.[dev]'
	touch $@

# A real browser for tests/test_view_browser.py: Debian's chromium and chromium-driver, installed with
# apt-get when missing (CI runs as root); elsewhere the test is skipped and says why.
$(VENV)/.browser: $(VENV)/.base
	@if command -v chromium >/dev/null 2>&1 && command -v chromedriver >/dev/null 2>&1; then \
		echo "browser: $$(command -v chromium), $$(command -v chromedriver)"; \
	elif command -v apt-get >/dev/null 2>&1 && [ "$$(id -u)" = 0 ]; then \
		echo "browser: installing chromium and chromium-driver (apt-get)"; \
		(apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium chromium-driver) \
			> $(VENV)/apt-browser.log 2>&1 || { tail -20 $(VENV)/apt-browser.log; exit 1; }; \
	else \
		echo "browser: no chromium and no root apt-get: tests/test_view_browser.py will be skipped"; \
	fi
	touch $@

demo: $(VENV)/.base
	$(UAMOPT) reproduce models/paper_case.toml --out out/paper_case

# Two pytest workers (pytest-xdist), one per core of the 2-core CI machine, each taking whole test files
# (a module's fixtures are then built once); TEST_WORKERS=0 runs serially.
TEST_WORKERS ?= 2

# ruff (ruff.toml) on the library and the tests, mypy with the pydantic plugin (mypy.ini)
lint: $(VENV)/.dev
	$(VENV)/bin/ruff check uamopt tests
	$(VENV)/bin/mypy

test: $(VENV)/.dev
	$(PY) -m pytest -n $(TEST_WORKERS) --dist loadfile

# The slow tests only (full-size notebooks, the 2,000-instance brute-force sweep, the 200-city search sweep, ...).
test-slow: $(VENV)/.dev
	$(PY) -m pytest -n $(TEST_WORKERS) --dist loadfile -m slow

test-all: $(VENV)/.dev
	$(PY) -m pytest -n $(TEST_WORKERS) --dist loadfile -m ''

$(VENV)/.notebooks: $(VENV)/.base
	$(PIP) -e '.[notebooks]'
	touch $@

# JupyterLab on the notebooks (full size); the kernel is this venv's Python, cwd the repository root.
notebooks: $(VENV)/.notebooks
	$(VENV)/bin/jupyter lab --notebook-dir=. notebooks/00_quickstart.ipynb

# Every notebook executed at full size, top to bottom, into out/notebooks/ (the committed files stay output-free).
notebooks-run: $(VENV)/.notebooks
	mkdir -p out/notebooks
	for nb in notebooks/*.ipynb; do \
		start=$$(date +%s); $(VENV)/bin/jupyter nbconvert --to notebook --execute \
			--ExecutePreprocessor.timeout=3600 --output-dir out/notebooks "$$nb" || exit 1; \
		echo "$$nb: $$(( $$(date +%s) - start )) s"; \
	done

bench: $(VENV)/.dev
	$(PY) tests/benchmarks/bench_risk.py

clean:
	rm -rf $(VENV) out build *.egg-info
