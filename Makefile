# flex: every target sets up .venv on first use (Python 3.11+ and make are all it needs).
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
export EXUDYN_NO_USER_SETTINGS := 1
export MPLBACKEND := Agg
RUN := $(PY) -m flex run

STUDIES := kinematics dynamics modal flexible spring

.PHONY: all test test-slow lint setup clean $(STUDIES)

all: $(STUDIES)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

setup: $(STAMP)

$(STUDIES): $(STAMP)
	$(RUN) $@

test: $(STAMP)
	$(PY) -m pytest -q

test-slow: $(STAMP)
	$(PY) -m pytest -q -m slow

lint: $(STAMP)
	$(PY) -m ruff check flex studies tests

clean:
	rm -rf results/*.h5 results/figures .cache
