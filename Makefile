# softdesign: `make demo` sets everything up and builds the sample case;
# `make test` runs the whole suite.  Both need only Python 3.11 and pip.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp

.PHONY: demo test bench install clean

install: $(STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $@

demo: $(STAMP)
	$(BIN)/softdesign build configs/demo.yaml --report
	@echo "Results in build/demo/: meshes/q_*.stl (the actuator at each q), kinematics.json,"
	@echo "manifest.json, and the report to open in a browser: build/demo/report/index.html"

test: $(STAMP)
	$(BIN)/python -m pytest

# `make bench`: per-stage time and peak memory of forced builds (sample case,
# VMTK aorta when ../shared/data is there, scaled synthetic case) against the
# I/O floor, with slopes against triangles and frames; about 3-4 minutes on a
# quiet machine (`--profile` adds per-stage hot spots).
bench: $(STAMP)
	$(BIN)/python pipelines/bench.py

clean:
	rm -rf build .pytest_cache

# `make golden`: build the sample cohort afresh and store its references in
# tests/golden/ (manifests, kinematics, decimated meshes, versions, case hashes).
# Run it only when a change to the meshes is intended; `make test` checks
# fresh builds against them.
.PHONY: golden
golden: $(STAMP)
	rm -rf build/golden-cohort
	$(MAKE) cohort COHORT=configs/cohort COHORT_BUILD=build/golden-cohort
	$(BIN)/python pipelines/golden.py --cohort configs/cohort --build build/golden-cohort --out tests/golden

include pipelines/cohort.mk
