# flex: every target sets up .venv on first use (Python 3.11+ and make are all it needs).
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
export EXUDYN_NO_USER_SETTINGS := 1
# Python caches compiled modules in __pycache__ unless PYTHONDONTWRITEBYTECODE is set (some
# shells and CI images set it): then every process -- each test worker, each spawned sweep
# worker, each `flex` subprocess -- compiles flex, scipy and the rest from source again
# (measured: the suite's collection 6.8 s instead of 2.7 s). The venv is installed without
# compiling every module of every package (~20 s); what runs is compiled once, on first import.
unexport PYTHONDONTWRITEBYTECODE
# OpenBLAS (numpy's, scipy's and NGsolve's each) starts a thread per core that spins between
# calls; with two studies at a time, their process pools and anyone else's jobs on the cores,
# the spinning took the cores from the work: the modal study alone beside another engineer's
# jobs (load ~5.5, 2 cores) took 87.5 s wall, 84.6 s CPU with the default and 37.1 s, 34.0 s
# with one thread (back to back). flex parallelizes over processes, not inside BLAS.
export OPENBLAS_NUM_THREADS := 1
export MPLBACKEND := Agg
RUN := $(PY) -m flex run

STUDIES := kinematics dynamics modal flexible spring wing crank kfit
# the order `make all` starts them in: the longest first, so that, two at a time, the last
# to start is a short one (the same studies as STUDIES)
ALL_ORDER := kfit crank flexible modal wing spring dynamics kinematics
# long runs, not part of `all` (README "Speed and accuracy", "Numerical stability"). On 2
# shared cores: tradeoff ~8 min (7.5 min measured warm), stability ~6-10 min, bench ~6 min
# (it times `make all FORCE=1` twice); `make all` itself took 2.6 min from a fresh
# clone with an empty cache on 2 quiet cores, 3.9 min on cores shared with other jobs (README).
# `flex run stability` exits 0 when exactly its runs built to diverge fail.
LONG := tradeoff stability bench estimates calibrate design validation ladder spring_mass references

# A study's result, results/<study>.h5 (and its figures, results/figures/<study>-*.png),
# is remade only when one of its inputs is newer: its module studies/<study>.py, or one of
# INPUTS -- the library (flex/**/*.py), its bundled scenes and data files (flex/data/scenes/*.toml;
# flex/config: the calibration -- fitted criteria, FFRF rule, solver defaults), studies/__init__.py and
# pyproject.toml. `make <study>` is an alias of `make results/<study>.h5`. FORCE=1 reruns
# the studies asked for anyway (`make all FORCE=1`, `make kfit FORCE=1`).
INPUTS := $(shell find flex -type f \( -name '*.py' -o -name '*.toml' \) \
	-not -path '*/__pycache__/*' | LC_ALL=C sort) studies/__init__.py pyproject.toml
RESULTS := $(STUDIES:%=results/%.h5)
LONG_RESULTS := $(LONG:%=results/%.h5)
MAKEFLAGS += --no-builtin-rules
.SUFFIXES:

.PHONY: all test test-slow lint setup clean calibration-install references-install \
	$(STUDIES) $(LONG) \
	force-rerun

# two studies at a time (JOBS=1: one after the other): most studies are a single process
# for much of their run (meshes, eigen-solves, figures, reports), so a second study fills
# the other core (measured from a fresh clone with an empty cache, 2 cores: 8.4 min one
# after the other, 5.2 min two at a time). Each progress line names its study.
JOBS ?= 2
ifneq ($(filter all,$(or $(MAKECMDGOALS),all)),)
MAKEFLAGS += -j$(JOBS)
endif
all: $(ALL_ORDER:%=results/%.h5)

# The engines are installed by uv (the same packages as pip; the set-up takes ~20 s instead
# of ~65 s, measured with warm download caches), by pip when uv cannot be had.
$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet uv && $(VENV)/bin/uv pip install --quiet --python $(PY) \
		-e '.[test]' || $(PY) -m pip install --quiet --no-compile -e '.[test]'
	touch $(STAMP)

setup: $(STAMP)

$(STUDIES) $(LONG): %: results/%.h5

# the .venv is order-only: (re)creating it reruns nothing; pyproject.toml is in INPUTS
$(RESULTS) $(LONG_RESULTS): results/%.h5: studies/%.py $(INPUTS) $(if $(FORCE),force-rerun) \
		| $(STAMP)
	$(run-study)

force-rerun: ;

# Run study $* for $@. A run that does not end as its study declares exits non-zero (flex
# run: 1 failed cases, 2 bad input, 3 internal error, 130/143 interrupted) and make stops;
# the target must then stay out of date for the next make. flex keeps an earlier result
# file as it was and writes the failed run beside it (<study>.failed.h5); only a first run
# (no earlier file) writes a failed run to $@ itself: it is moved to <study>.failed.h5 here.
# Whatever else changed $@ in a failed run (an interrupt while drawing figures) gets $@'s
# earlier time stamp back, kept in results/.<study>.h5.before during the run.
# `kill <make>` (SIGTERM) reaches only make's shells: each passes it on to its flex run and
# waits for it to end (before, the shell died, flex and its workers computed on, and
# .<study>.h5.before stayed behind). A Ctrl-C reaches flex from the terminal itself.
define run-study
@before=$(@D)/.$(@F).before; mkdir -p $(@D); \
if [ -e $@ ]; then touch -r $@ $$before; else rm -f $$before; fi; \
echo "$(RUN) $*"; \
run=; stop=; trap 'stop=TERM; [ -n "$$run" ] && kill -TERM $$run 2>/dev/null' TERM HUP; \
trap : INT; $(RUN) $* & run=$$!; [ -n "$$stop" ] && kill -TERM $$run 2>/dev/null; \
wait $$run; status=$$?; \
while kill -0 $$run 2>/dev/null; do wait $$run; status=$$?; done; \
[ $$status -eq 0 ] || { \
	if [ -e $$before ]; then touch -r $$before $@; \
	elif [ -e $@ ]; then mv -f $@ $(@:.h5=.failed.h5); \
		echo "make: $@ came from a failed run: moved to $(@:.h5=.failed.h5)" >&2; fi; \
	rm -f $$before; exit $$status; }; \
rm -f $$before
endef

# kfit and crank write their fitted laws beside their results, before their validation
# phase: a law is installed only from an up-to-date run that did not fail afterwards
results/kfit-criterion.toml results/crank-criterion.toml: results/%-criterion.toml: \
		results/%.h5
	@test -f $@ || { echo "make: $@ is missing although $< is up to date;" \
		"rerun with 'make $* FORCE=1'" >&2; exit 1; }
	@if [ $(<:.h5=.failed.h5) -nt $< ]; then echo "make: the last $* run failed" \
		"($(<:.h5=.failed.h5)): its law $@ is not installed" >&2; exit 1; fi

# calibrate stores its fitted FFRF settings rule in its result file: written out beside it
results/calibrate-rule.toml: results/calibrate.h5 | $(STAMP)
	$(PY) -m flex.experiments.fitting.calibration_report $< $@

# after make kfit, make crank and/or make calibrate: install their fits as the bundled
# calibration (flex/config/: criteria_fit.toml, crank_criteria_fit.toml, ffrf_rule.toml, what
# every "auto" reads; commit them), in one step (flex.config.calibration.install_calibration).
# FITS names which (default: all three; a fit's study runs first if it is out of date). Every
# study reads the calibration: they are all out of date after an install.
FITS ?= kfit crank calibrate
FIT_FILES = $(foreach fit,$(FITS),results/$(fit)-$(if $(filter calibrate,$(fit)),rule,criterion).toml)
calibration-install: $(FIT_FILES) | $(STAMP)
	$(PY) -m flex.config.calibration install --into flex/config $^

# estimates, calibrate and flexible judge against the bundled store: a new store makes them out
# of date
results/estimates.h5 results/calibrate.h5 results/flexible.h5: flex/data/references.h5
# a study's scene list beside its module (studies/<study>.toml) is its input too; references
# makes every calibrate scene's physics, estimates reads the references' physics list
STUDY_TOMLS := $(wildcard studies/*.toml)
$(STUDY_TOMLS:studies/%.toml=results/%.h5): results/%.h5: studies/%.toml
results/references.h5: studies/calibrate.toml
results/estimates.h5: studies/references.toml

# after make references: its converged references become the bundled store every judging
# study reads (flex/data/references.h5: commit it; make estimates and make calibrate read it)
references-install: results/references.h5 | $(STAMP)
	$(PY) -m flex.experiments.workprecision.stored_references install $< flex/data/references.h5

test: $(STAMP)
	$(PY) -m pytest -q -n 2 --dist worksteal

test-slow: $(STAMP)
	$(PY) -m pytest -q -n 2 -m slow

lint: $(STAMP)
	$(PY) -m ruff check flex studies tests

clean:
	rm -rf results/*.h5 results/.*.h5.before results/figures results/reports .cache \
		results/kfit-cases results/calibrate-cases results/kfit-criterion.toml results/crank-criterion.toml \
		results/calibrate-rule.toml
