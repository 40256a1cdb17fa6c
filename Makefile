# Set-up and everyday commands. A fresh machine needs only python3 (with pip and venv).
# Every install takes its versions from the committed lock, requirements/lock.txt
# (`make lock` refreshes it); `make test-latest` tries the newest releases instead.
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip
OUT    ?= runs/demo
LOCK   := requirements/lock.txt
EXTRAS := test,reference,dev
# the core packages, type-checked with --strict by `make lint`
STRICT := trackplan/paths trackplan/robots trackplan/timing trackplan/planning \
          trackplan/profiles trackplan/tool

.PHONY: run test test-fast test-latest test-lowest bench lint lock browser docs clean

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PIP) install --quiet --upgrade pip

# One stamp per set of extras: reinstall when pyproject.toml or the lock changes.
$(VENV)/.installed-base: pyproject.toml $(LOCK) | $(PY)
	$(PIP) install --quiet --constraint $(LOCK) -e .
	touch $@

$(VENV)/.installed-test: pyproject.toml $(LOCK) | $(PY)
	$(PIP) install --quiet --constraint $(LOCK) -e '.[$(EXTRAS)]'
	touch $@

## run: install from the lock and run the paper's corner case end to end (optimize + report)
run: $(VENV)/.installed-base
	$(VENV)/bin/trackplan demo --out $(OUT)

## test: install from the lock with the test extras and run the whole suite
## (the browser tests skip with one line unless `make browser` has installed Chromium)
test: $(VENV)/.installed-test
	$(PY) -m pytest -n 2 -q

## test-fast: the fast tier (no end-to-end tests), under two minutes
test-fast: $(VENV)/.installed-test
	$(PY) -m pytest -n 2 -q -m "not slow"

## test-latest: a fresh venv with the newest release of every dependency, then the suite
test-latest:
	rm -rf .venv-latest
	$(PYTHON) -m venv .venv-latest
	.venv-latest/bin/python -m pip install --quiet --upgrade pip
	.venv-latest/bin/python -m pip install --quiet --upgrade -e '.[$(EXTRAS)]'
	.venv-latest/bin/python -m pip list --format=freeze > .venv-latest/versions.txt
	.venv-latest/bin/python -m pytest -n 2 -q -p no:cacheprovider

## test-lowest: a fresh venv at the lower bounds that pyproject.toml states, then the suite
test-lowest: $(VENV)/.installed-test
	rm -rf .venv-lowest
	$(PYTHON) -m venv .venv-lowest
	.venv-lowest/bin/python -m pip install --quiet --upgrade pip
	$(VENV)/bin/uv pip compile pyproject.toml --extra test --extra reference --extra dev \
	  --resolution lowest-direct --python .venv-lowest/bin/python --quiet -o .venv-lowest/lowest.txt
	.venv-lowest/bin/python -m pip install --quiet --constraint .venv-lowest/lowest.txt -e '.[$(EXTRAS)]'
	.venv-lowest/bin/python -m pytest -n 2 -q -p no:cacheprovider

## lock: refresh requirements/lock.txt from pyproject.toml (newest releases that fit)
lock: $(VENV)/.installed-test
	$(VENV)/bin/uv pip compile pyproject.toml --extra test --extra reference --extra dev \
	  --universal --python-version 3.11 --quiet -o $(LOCK)

## browser: Debian's Chromium for the report's browser tests (installs with apt-get, as root)
browser:
	@if command -v chromium >/dev/null 2>&1; then echo "browser: $$(command -v chromium) is there"; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	  echo "browser: installing Debian's chromium package (about 300 MB) with apt-get, for tests/report/test_browser.py"; \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null \
	    && echo "browser: installed $$(command -v chromium)"; \
	else echo "browser: install Debian's chromium package as root (apt-get install chromium) to run the browser tests"; exit 1; fi

## bench: the benchmarks (ratios against references measured in the same run)
bench: $(VENV)/.installed-test
	$(PY) -m benchmarks

## lint: ruff (lint and format), mypy (--strict on the core) and the layer contract, as CI runs them
lint: $(VENV)/.installed-test
	$(VENV)/bin/ruff check trackplan tests benchmarks
	$(VENV)/bin/ruff format --check trackplan tests benchmarks
	$(VENV)/bin/mypy trackplan
	$(VENV)/bin/mypy --strict --follow-imports=silent $(STRICT)
	$(VENV)/bin/lint-imports

## docs: re-run every command the docs quote and rewrite their figures and screenshots
docs: $(VENV)/.installed-test browser
	$(PY) -m tests.docs.regenerate

clean:
	rm -rf $(VENV) .venv-latest .venv-lowest runs .pytest_cache .hypothesis
