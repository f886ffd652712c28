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
	$(BIN)/softdesign build configs/demo.yaml
	@echo "Results: build/demo/ (manifest.json and the stage folders)"

test: $(STAMP)
	$(BIN)/python -m pytest

clean:
	rm -rf build .pytest_cache
