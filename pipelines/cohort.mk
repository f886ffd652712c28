# Cohort builds, included by the top-level Makefile.
#
#   make cohort                         every case file configs/cohort/*.yaml
#   make -j4 cohort COHORT=DIR          another folder of case files, four cases at a time
#   make cohort COHORT_BUILD=DIR        build folders elsewhere (default: build/)
#
# Each case file DIR/<case>.yaml is one target, BUILD/<case>/manifest.json,
# which softdesign writes last and only when every stage succeeded.  It
# depends on the case file and on the files the case reads (listed in
# BUILD/.deps/<case>.mk, remade when the case file changes), so a re-run
# rebuilds only the cases whose case file or inputs changed.  A change to
# softdesign itself does not rebuild anything: `make cohort-clean cohort`.
#
# A case's output goes to BUILD/<case>.log and its outcome to
# BUILD/<case>.status.json; a failing case does not stop the others.  The
# table BUILD/cohort-summary.csv (one row per case: status, fit RMS/p99,
# stretch, rho*kappa, min radius, wall, volumes, time, the error message) is
# remade at the end, and make exits non-zero when any case failed.  A failed
# case keeps its previous build (if any) untouched and out of date, so the
# next `make cohort` tries it again.

COHORT ?= configs/cohort
COHORT_BUILD ?= build
COHORT_PYTHON ?= $(BIN)/python
COHORT_SOFTDESIGN ?= $(BIN)/softdesign
# Worker processes per case build (softdesign build --jobs): make -jN already builds N cases at a
# time, so each case runs in one process; raise it for a few large cases on a machine with cores to spare.
COHORT_JOBS ?= 1
# What a case build needs first (not a reason to rebuild): the installed venv and the package's bytecode
# (`make bytecode`: a cohort starts a softdesign process per case and stage).
COHORT_NEEDS ?= bytecode
COHORT_TOOL = $(COHORT_PYTHON) pipelines/cohort_tool.py

COHORT_DIR := $(patsubst %/,%,$(COHORT))
COHORT_CASES := $(sort $(basename $(notdir $(wildcard $(COHORT_DIR)/*.yaml))))
COHORT_STAMPS := $(COHORT_CASES:%=$(COHORT_BUILD)/%/manifest.json)
COHORT_DEPS := $(COHORT_CASES:%=$(COHORT_BUILD)/.deps/%.mk)
COHORT_SUMMARY := $(COHORT_BUILD)/cohort-summary.csv

.PHONY: cohort cohort-clean cohort-sample

cohort: $(COHORT_SUMMARY)

# The folder is a prerequisite too: adding or removing a case file remakes the table.
$(COHORT_SUMMARY): $(COHORT_STAMPS) $(COHORT_DIR) | $(COHORT_NEEDS)
	@$(COHORT_TOOL) summary --cohort $(COHORT_DIR) --build $(COHORT_BUILD) --out $@

$(COHORT_BUILD)/%/manifest.json: $(COHORT_DIR)/%.yaml | $(COHORT_NEEDS)
	@echo "cohort: building $* ($<)"
	@$(COHORT_TOOL) run --case $* --log $(COHORT_BUILD)/$*.log --status $(COHORT_BUILD)/$*.status.json \
		-- $(COHORT_SOFTDESIGN) build $< --out $(COHORT_BUILD)/$* --jobs $(COHORT_JOBS)

$(COHORT_BUILD)/.deps/%.mk: $(COHORT_DIR)/%.yaml | $(COHORT_NEEDS)
	@$(COHORT_TOOL) deps $< --target $(COHORT_BUILD)/$*/manifest.json --out $@

# The input lists are read (and remade first when stale) only when a cohort is being built.
ifneq ($(filter cohort,$(MAKECMDGOALS)),)
ifeq ($(COHORT_CASES),)
$(error COHORT=$(COHORT): no *.yaml case files there; give COHORT=DIR, a folder of case files)
endif
-include $(COHORT_DEPS)
endif

cohort-clean:
	rm -rf $(COHORT_STAMPS:%/manifest.json=%) $(COHORT_DEPS) $(COHORT_SUMMARY) \
		$(COHORT_CASES:%=$(COHORT_BUILD)/%.log) $(COHORT_CASES:%=$(COHORT_BUILD)/%.status.json)

# Regenerate the sample cohort's inputs (committed; tests compare them with the generator's output).
cohort-sample: | $(COHORT_NEEDS)
	$(COHORT_TOOL) sample data/cohort
