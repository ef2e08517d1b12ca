# Loose-joint workbench.  `make` lists the targets.
.DEFAULT_GOAL := help
SHELL := /bin/bash

PYTHON_SYS ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
RESULTS := results

.PHONY: help setup test bench study clean modes

help:  ## list the targets
	@awk 'BEGIN {FS = ":.*## "} /^[a-zA-Z_-]+:.*## / {printf "  make %-8s %s\n", $$1, $$2}' $(MAKEFILE_LIST)

$(STAMP): pyproject.toml
	@command -v $(PYTHON_SYS) >/dev/null || { echo "need $(PYTHON_SYS) (set PYTHON_SYS=...)"; exit 1; }
	test -x $(PY) || $(PYTHON_SYS) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

setup: $(STAMP)  ## create .venv and install the package (editable) with dev extras

test: $(STAMP)  ## run the test suite (physics checks included)
	$(PY) -m pytest -q

bench: $(STAMP)  ## run the benchmarks (pytest-benchmark), save JSON under .benchmarks/
	$(PY) -m pytest -q benchmarks --benchmark-only --benchmark-enable --benchmark-autosave \
		--benchmark-columns=min,median,max,rounds -p no:randomly

study: $(RESULTS)/modes/modes.md  ## run the main study (today: the modal table of the model)

$(RESULTS)/modes/modes.md: $(STAMP) studies/modes.py $(wildcard workbench/*.py workbench/core/*.py)
	$(PY) studies/modes.py --out $(RESULTS)/modes

clean:  ## remove generated results (keeps results/README.md) and caches
	find $(RESULTS) -mindepth 1 ! -name README.md -exec rm -rf {} +
	find . -name __pycache__ -prune -exec rm -rf {} +
