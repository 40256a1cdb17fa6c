# Set-up and everyday commands. A fresh machine needs only python3 (with pip and venv).
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip
OUT    ?= runs/demo

.PHONY: run test bench lint browser clean

$(PY):
	$(PYTHON) -m venv $(VENV)
	$(PIP) install --quiet --upgrade pip

# One stamp per set of extras: reinstall when pyproject.toml changes.
$(VENV)/.installed-base: pyproject.toml | $(PY)
	$(PIP) install --quiet -e .
	touch $@

$(VENV)/.installed-test: pyproject.toml | $(PY)
	$(PIP) install --quiet -e '.[test,reference,dev]'
	touch $@

## run: install and run the paper's corner case end to end (optimize + report)
run: $(VENV)/.installed-base
	$(VENV)/bin/trackplan demo --out $(OUT)

## browser: headless Chromium for the report test (Debian package), when missing
browser:
	@command -v chromium >/dev/null 2>&1 || { \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null) \
	      || echo "WARNING: could not install chromium; browser tests will be skipped"; \
	  else echo "WARNING: chromium missing and cannot be installed here; browser tests will be skipped"; fi; }

## test: install with test extras and run the whole suite
test: $(VENV)/.installed-test browser
	$(PY) -m pytest -n 2 -q

## bench: the benchmarks (ratios against references measured in the same run)
bench: $(VENV)/.installed-test
	$(PY) -m benchmarks

## lint: ruff (lint and format) and mypy, as CI runs them
lint: $(VENV)/.installed-test
	$(VENV)/bin/ruff check trackplan tests benchmarks
	$(VENV)/bin/ruff format --check trackplan tests benchmarks
	$(VENV)/bin/mypy trackplan

## docs: re-run every command the docs quote and rewrite their figures and screenshots
.PHONY: docs
docs: $(VENV)/.installed-test browser
	$(PY) -m tests.docs.regenerate

clean:
	rm -rf $(VENV) runs .pytest_cache .hypothesis
