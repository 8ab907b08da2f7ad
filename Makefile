# Set-up is part of every target: a fresh clone needs only `make demo` and `make test`.
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed-stamp

.PHONY: demo test fuzz bench install clean

# Re-install when the project file or the package list changes (an editable install maps
# the packages that existed when it ran).
$(STAMP): pyproject.toml $(wildcard */__init__.py)
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[test]"
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/feedoracle compare examples/demo.mpf --report reports --json reports/demo.json

test: $(STAMP)
	$(PY) -m pytest -q -n 2 --dist loadgroup

# The fuzz suite alone with many random examples (tests/fuzz; `make test` runs a small
# derandomized set of it). FEEDORACLE_FUZZ_EXAMPLES / FEEDORACLE_FUZZ_SEEDS set the counts.
fuzz: $(STAMP)
	FEEDORACLE_FUZZ=1 $(PY) -m pytest -q -n 2 --dist loadgroup tests/fuzz \
		--hypothesis-show-statistics

bench: $(STAMP)
	$(PY) tests/bench/run_all.py

clean:
	rm -rf $(VENV) .hypothesis reports/*.html reports/*.json reports/*.csv
