# softdesign: `make demo` sets everything up and builds the sample case;
# `make test` runs the whole suite.  Both need only Python 3.11 and pip.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
# Exact versions of every package the venv holds (and of setuptools for the
# editable build): the same environment on every machine.  `make lock` remakes it.
CONSTRAINTS := requirements/constraints.txt
LOCK_VENV := build/.lock-venv
# Snakemake and its SLURM executor (pyproject's [cluster] extra) for pipelines/Snakefile, in a venv of
# their own: snakemake pins packaging<26, which the main venv's lock does not allow.  `make lock-cluster`.
CLUSTER_VENV := .venv-cluster
CLUSTER_STAMP := $(CLUSTER_VENV)/.installed-stamp
CLUSTER_CONSTRAINTS := requirements/cluster.txt
CLUSTER_PACKAGES = $$($(PYTHON) -c 'import tomllib; print(" ".join(tomllib.load(open("pyproject.toml", "rb"))["project"]["optional-dependencies"]["cluster"]))')

.PHONY: demo test test-fast lint lock lock-cluster bench study study-property test-seconds install clean bytecode

install: $(STAMP) $(CLUSTER_STAMP)

# A fresh venv each time (--clear), so a package dropped from the pins leaves it too.
# The venv's own pip predates --build-constraint: it first installs the pinned pip.
# Quiet: one line says what it does.  setuptools' "Editable installation" notice (a folder named softdesign in the
# directory you run Python from would shadow the installed package) is the only thing pip --quiet lets through: it
# is silenced by its message (PYTHONWARNINGS), and said here instead.
$(STAMP): pyproject.toml $(CONSTRAINTS)
	@echo "make: a fresh $(VENV) with the pinned packages ($(CONSTRAINTS)) and softdesign installed editable (a minute or two)"
	@$(PYTHON) -m venv --clear $(VENV)
	@$(BIN)/python -m pip install --quiet -c $(CONSTRAINTS) pip setuptools
	@PYTHONWARNINGS="ignore:Editable installation" \
		$(BIN)/python -m pip install --quiet -c $(CONSTRAINTS) --build-constraint $(CONSTRAINTS) -e '.[test,lint]'
	@touch $@

# The workflow engine only (the workflow runs softdesign from .venv); its pins: requirements/cluster.txt.
$(CLUSTER_STAMP): pyproject.toml $(CLUSTER_CONSTRAINTS)
	@echo "make: a fresh $(CLUSTER_VENV) with snakemake and its SLURM executor ($(CLUSTER_CONSTRAINTS))"
	@$(PYTHON) -m venv --clear $(CLUSTER_VENV)
	@$(CLUSTER_VENV)/bin/python -m pip install --quiet -c $(CLUSTER_CONSTRAINTS) pip setuptools
	@$(CLUSTER_VENV)/bin/python -m pip install --quiet -c $(CLUSTER_CONSTRAINTS) --build-constraint $(CLUSTER_CONSTRAINTS) \
		$(CLUSTER_PACKAGES)
	@touch $@

# `make lock`: on purpose only.  Resolves the newest releases pyproject.toml
# allows in a throwaway venv and pins all of them; then `make install test`.
lock:
	rm -rf $(LOCK_VENV)
	$(PYTHON) -m venv --clear $(LOCK_VENV)
	$(LOCK_VENV)/bin/python -m pip install --quiet --upgrade pip setuptools
	$(LOCK_VENV)/bin/python -m pip install --quiet -e '.[test,lint]'
	mkdir -p $(dir $(CONSTRAINTS))
	{ echo "# Exact versions of every package 'make install' puts in .venv (direct and transitive)."; \
	  echo "# Made by 'make lock' (the newest releases pyproject.toml allows) on $$(date -u +%Y-%m-%d)"; \
	  $(LOCK_VENV)/bin/python -c 'import platform; print("# with", platform.python_implementation(), platform.python_version(), "on", platform.platform())'; \
	  echo "# Do not edit by hand: change pyproject.toml, run 'make lock', then 'make install test'."; \
	  $(LOCK_VENV)/bin/python -m pip freeze --all --exclude-editable; } > $(CONSTRAINTS).new
	mv $(CONSTRAINTS).new $(CONSTRAINTS)
	rm -rf $(LOCK_VENV)

# `make lock-cluster`: on purpose only, as `make lock`, for the [cluster] extra's venv.
lock-cluster:
	rm -rf $(LOCK_VENV)
	$(PYTHON) -m venv --clear $(LOCK_VENV)
	$(LOCK_VENV)/bin/python -m pip install --quiet --upgrade pip setuptools
	$(LOCK_VENV)/bin/python -m pip install --quiet $(CLUSTER_PACKAGES)
	{ echo "# Exact versions of every package 'make install' puts in $(CLUSTER_VENV) (snakemake, its SLURM executor, their deps)."; \
	  echo "# Made by 'make lock-cluster' (the newest releases pyproject.toml's [cluster] extra allows) on $$(date -u +%Y-%m-%d)"; \
	  $(LOCK_VENV)/bin/python -c 'import platform; print("# with", platform.python_implementation(), platform.python_version(), "on", platform.platform())'; \
	  echo "# Do not edit by hand: change pyproject.toml, run 'make lock-cluster', then 'make install test'."; \
	  $(LOCK_VENV)/bin/python -m pip freeze --all; } > $(CLUSTER_CONSTRAINTS).new
	mv $(CLUSTER_CONSTRAINTS).new $(CLUSTER_CONSTRAINTS)
	rm -rf $(LOCK_VENV)

# The package's bytecode, compiled ahead as a wheel install does.  An editable install leaves it to Python,
# and where PYTHONDONTWRITEBYTECODE is set (as on this project's CI machines) every command compiled the
# package's modules again (about 0.1 s of each command's start).  A stale file is only ignored: Python checks it
# against the source's time stamp and size.
bytecode: $(STAMP)
	@$(BIN)/python -m compileall -q softdesign

# What it makes is said first: the build's own last lines are its verdict and its folder.
demo: bytecode
	@echo "make: softdesign build configs/demo.yaml --report: build/demo/ gets meshes/q_*.stl (the actuator at each q),"
	@echo "      kinematics.json, manifest.json, fabrication.md and the report to open: build/demo/report/index.html"
	@$(BIN)/softdesign build configs/demo.yaml --report

# pytest-xdist: one worker per core (-n auto; CI's machines have 2), whole files to a worker (--dist loadfile:
# a file's module caches and module-scoped builds are made once, its tests never race each other for them), the
# longest files first (--no-loadscope-reorder keeps the order tests/conftest.py gives them from the seconds of the
# last run, tests/helpers/schedule.py; xdist's own order, the most tests first, left the slow files of one or two
# tests to the end), and the slowest 15 tests printed at the end.  How to keep a test safe in parallel: tests/conftest.py.
# `bytecode` first: the suite starts softdesign in child processes (43 call sites, some in loops), and with
# PYTHONDONTWRITEBYTECODE set (CI) each child compiled the modules it imports again (validate's: ~0.17 s of CPU).
# PYTEST runs with PYTHONDONTWRITEBYTECODE unset: pytest keeps the test modules it rewrites for its assertions
# (tests/**/__pycache__/*-pytest-*.pyc, ignored by git) only where Python may write bytecode; with it set, every
# xdist worker rewrote all ~245 test files at every run (collection 7.0 s of CPU a worker, 2.6 s from the kept
# files).  A fresh clone (CI) rewrites them once, as before.
PYTEST := env -u PYTHONDONTWRITEBYTECODE $(BIN)/python -m pytest
PYTEST_PARALLEL := -n auto --dist loadfile --no-loadscope-reorder --durations=15
test: bytecode $(CLUSTER_STAMP)
	$(PYTEST) $(PYTEST_PARALLEL)

# Everything but the tests marked slow (whole builds, cohorts, reports).
test-fast: bytecode $(CLUSTER_STAMP)
	$(PYTEST) $(PYTEST_PARALLEL) -m "not slow"

# `make test-seconds`: after a full `make test`, write each file's seconds from pytest's cache to
# tests/file_seconds.json, the order a fresh clone (CI) starts the files in.  Commit it when the order moved.
test-seconds:
	$(BIN)/python -m tests.helpers.schedule

# `make study`: re-derive the nested-refinement studies' recorded levels
# (tests/mechanics/refinement_reference*.json: bare and with the sample case's hoop thread, 12-25 minutes of
# CPU each, threaded with round chambers, two levels, about 2 minutes, and threaded with curved chamber walls,
# three levels, about 12 minutes); `make study STUDY=thread` re-derives
# one (STUDY=thread-six: the thread's six-point rule, not read by the tests, much longer).  `make test` solves
# the coarse level and says to run this when it no longer matches the record.
study: $(STAMP)
	$(BIN)/python pipelines/study.py $(if $(STUDY),--study $(STUDY))

# `make study-property`: the incremental-build property (tests/pipeline/test_incremental_property.py) with 20 drawn
# examples beside its written ones (about 2 minutes); `make test` draws 5.
study-property: bytecode
	SOFTDESIGN_PROPERTY_EXAMPLES=20 $(PYTEST) -n 0 tests/pipeline/test_incremental_property.py

# ruff (style, imports, bugbear, pyupgrade, numpy rules) and mypy, both
# configured in pyproject.toml; both run, and either failing fails the target.
lint: $(STAMP)
	@status=0; \
	$(BIN)/ruff check . || status=1; \
	$(BIN)/mypy || status=1; \
	exit $$status

# `make bench`: per-stage time and peak memory of forced builds (sample case,
# VMTK aorta when ../shared/data is there, scaled synthetic case) against the
# I/O floor, with slopes against triangles and frames; about 3-4 minutes on a
# quiet machine (`--profile` adds per-stage hot spots).
bench: bytecode
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
