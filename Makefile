# flex: every target sets up .venv on first use (Python 3.11+ and make are all it needs).
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
export EXUDYN_NO_USER_SETTINGS := 1
export MPLBACKEND := Agg
RUN := $(PY) -m flex run

STUDIES := kinematics dynamics modal flexible spring wing crank kfit

.PHONY: all test test-slow lint setup clean kfit-criterion crank-criterion $(STUDIES)

all: $(STUDIES)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

setup: $(STAMP)

$(STUDIES): $(STAMP)
	$(RUN) $@

# long runs, not part of `all` (README "Speed and accuracy", "Numerical stability"); each
# writes results/<target>.h5 and figures. On 2 shared cores: tradeoff ~65 min, stability
# ~10 min, bench ~23 min (it runs `make all` twice); `make all` itself takes 8-11 min.
# `flex run stability` exits 0 when exactly its runs built to diverge fail.
LONG := tradeoff stability bench
.PHONY: $(LONG)
$(LONG): $(STAMP)
	$(RUN) $@

# after make kfit: install its fit as the criterion that model = "auto" reads (commit it)
kfit-criterion: results/kfit-criterion.toml
	cp results/kfit-criterion.toml flex/criteria_fit.toml

# after make crank: install the crank's law that crank.model = "auto" reads (commit it)
crank-criterion: results/crank-criterion.toml
	cp results/crank-criterion.toml flex/crank_criteria_fit.toml

test: $(STAMP)
	$(PY) -m pytest -q

test-slow: $(STAMP)
	$(PY) -m pytest -q -m slow

lint: $(STAMP)
	$(PY) -m ruff check flex studies tests

clean:
	rm -rf results/*.h5 results/figures .cache results/kfit-cases results/kfit-criterion.toml \
		results/crank-criterion.toml
