# Loose-joint workbench.  `make` lists the targets.
.DEFAULT_GOAL := help
SHELL := /bin/bash

PYTHON_SYS ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
RESULTS := results

.PHONY: help setup test bench study branches shaker-200n stress sensitivity paper-fit clean

help:  ## list the targets
	@awk 'BEGIN {FS = ":.*## "} /^[a-zA-Z_-]+:.*## / {printf "  make %-8s %s\n", $$1, $$2}' $(MAKEFILE_LIST)

# The installed modules' bytecode is compiled on every core (compileall -j 0), not by pip
# in one process, and not for the packages' own test folders: 35 s against pip's 68 s for
# the install.  It must be there: where PYTHONDONTWRITEBYTECODE is set (as on these
# machines), Python never writes it on import.
$(STAMP): pyproject.toml
	@command -v $(PYTHON_SYS) >/dev/null || { echo "need $(PYTHON_SYS) (set PYTHON_SYS=...)"; exit 1; }
	test -x $(PY) || $(PYTHON_SYS) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet --no-compile -e '.[dev]'
	$(PY) -m compileall -q -j 0 -x '/tests?/' "$$($(PY) -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"
	$(PY) -m workbench compile
	touch $(STAMP)

setup: $(STAMP)  ## create .venv, install the package (editable) with dev extras, compile the kernels

# Test modules run in parallel processes, one module's tests in one process (its fixtures once),
# the longest modules first (tests/conftest.py).
test: $(STAMP)  ## run the test suite (physics checks included)
	$(PY) -m pytest -q -n auto --dist loadscope --no-loadscope-reorder

# About 46 minutes on a 2-core Ice Lake Xeon: a cold compile (1), `make study` whole (35), LSODA on windows, the default grid twice (1 s per point).
bench: $(STAMP)  ## run the benchmarks (pytest-benchmark): JSON under .benchmarks/, tables in docs/performance.md and README.md
	$(PY) -m pytest -q benchmarks --benchmark-only --benchmark-enable --benchmark-autosave \
		--benchmark-columns=min,median,max,rounds -p no:randomly
	$(PY) benchmarks/summarise.py --out benchmarks/results.md --readme docs/performance.md \
		--targets README.md

# The studies of `make study` (studies/<name>.toml -> results/<name>/report.md).
STUDIES := free_decay stepped chirp shaker damage period_doubling
SOURCES := $(shell find workbench -name "*.py" -not -path "*/__pycache__/*")

study: $(RESULTS)/index.md  ## run every study (shaker grid, chirps, free decays, stepped sweeps, damage map, period doubling at 20 Hz, modes, identification, estimator)

$(RESULTS)/index.md: $(foreach s,$(STUDIES),$(RESULTS)/$(s)/report.md) $(RESULTS)/modes/modes.md \
		$(RESULTS)/identification/identification.md $(RESULTS)/estimate/estimate.md \
		$(RESULTS)/paper/report.md studies/index.py
	$(PY) studies/index.py $(RESULTS) $(STUDIES) modes identification estimate paper

# Exit status 3: the sweep finished but some points failed; they are listed in the report.
$(RESULTS)/%/report.md: studies/%.toml $(SOURCES) $(STAMP)
	$(PY) -m workbench sweep $< --results $(RESULTS) || [ $$? -eq 3 ]

# The paper's section 6 observations measured in the model, each with a verdict, and where the
# period-1 orbit at 20 Hz loses stability (the period doubling study).
$(RESULTS)/paper/report.md: $(STAMP) studies/paper.py $(SOURCES) $(RESULTS)/period_doubling/report.md
	$(PY) studies/paper.py --out $(RESULTS)/paper

# The branches of periodic orbits over the stepped study's frequencies, beside its points: not
# part of `make study`.
branches: $(RESULTS)/branches/report.md  ## periodic orbits over 10-55 Hz at both gaps against the stepped sweeps (over an hour on 2 cores)

$(RESULTS)/branches/report.md: $(RESULTS)/stepped/report.md

# Which parameter decides each of the paper's observations: not part of `make study`.
sensitivity: $(RESULTS)/sensitivity/short_runs.md  ## Sobol' indices of the paper's observations (1 664 runs, about an hour)

# The design's 3 s runs against 10 s runs on 16 of its points, and its band proxy against 8
# real chirps; the report then links the checks.
$(RESULTS)/sensitivity/short_runs.md: $(RESULTS)/sensitivity/report.md studies/sensitivity_check.py
	$(PY) studies/sensitivity_check.py studies/sensitivity.toml --results $(RESULTS) --chirps 8
	$(PY) -m workbench report studies/sensitivity.toml --results $(RESULTS)

# The inverse question: the estimator on the paper's observations, from the design's best points.
paper-fit: $(RESULTS)/paper_fit/all/report.md  ## search the ranges for a set showing the paper's observations together (after `make sensitivity`; about 50 minutes)

$(RESULTS)/paper_fit/all/report.md: $(RESULTS)/sensitivity/short_runs.md studies/paper_fit.py
	$(PY) studies/paper_fit.py --out $(RESULTS)/paper_fit --design $(RESULTS) --starts 2
	$(PY) -m workbench report studies/sensitivity.toml --results $(RESULTS)

# The shaker grid at 200 N at every point (the paper's comparison level; most points leave the
# validated range, which its report lists): not part of `make study`.
shaker-200n: $(RESULTS)/shaker_200n/report.md  ## the shaker grid at a fixed 200 N (about 5 minutes)

# The paper's operating range driven hard (MODEL.md §5-§7): not part of `make study`.
STRESS := stress stress_paper stress_chirp
stress: $(foreach s,$(STRESS),$(RESULTS)/$(s)/report.md)  ## the stress studies: every gap, 10-55 Hz, 20-200 N, chirps (hours: `workbench sweep STUDY --dry-run` estimates each)
	$(PY) studies/stress_check.py $(RESULTS) $(STRESS)

$(RESULTS)/modes/modes.md: $(STAMP) studies/modes.py $(SOURCES)
	$(PY) studies/modes.py --out $(RESULTS)/modes

# The paper's Tables 3-6 and Appendix B reproduced.
$(RESULTS)/identification/identification.md: $(STAMP) $(SOURCES)
	$(PY) -m workbench identify tables --out $(RESULTS)/identification

# The parameter estimator on synthetic .lvm records with hidden values.
$(RESULTS)/estimate/estimate.md: $(STAMP) studies/estimate_demo.py $(SOURCES)
	$(PY) studies/estimate_demo.py --out $(RESULTS)/estimate

clean:  ## remove generated results (keeps results/README.md) and caches
	find $(RESULTS) -mindepth 1 ! -name README.md -exec rm -rf {} +
	find . -name __pycache__ -prune -exec rm -rf {} +
