# The two commands a newcomer needs: `make demo` and `make test`.
# Both create .venv on first use and install the package with every extra, plus the test
# tools (requirements-dev.txt), from PyPI.
# Nothing is cached outside this folder: pip, matplotlib and ROS logs live under .cache/.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp

export PIP_CACHE_DIR := $(CURDIR)/.cache/pip
export MPLCONFIGDIR := $(CURDIR)/.cache/matplotlib
export MPLBACKEND := Agg
export ROS_LOG_DIR := $(CURDIR)/.cache/ros/log
export ROS_HOME := $(CURDIR)/.cache/ros
export ROS_AUTOMATIC_DISCOVERY_RANGE ?= LOCALHOST
export PYTHONDONTWRITEBYTECODE :=

.PHONY: venv demo test test-slow lint typecheck bench clean

$(STAMP): setup.py setup.cfg package.xml requirements.txt requirements-dev.txt
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -r requirements-dev.txt
	@touch $@

venv: $(STAMP)

demo: venv
	$(BIN)/lumpbeam demo --out results

test: venv
	$(BIN)/ruff check .
	$(BIN)/mypy
	$(BIN)/python -m pytest

# The long validation matrices (marked slow): CI runs them after `make test`.
test-slow: venv
	$(BIN)/python -m pytest -m slow

lint: venv
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

# Strict static types of the ROS-free core (the module list is in mypy.ini).
typecheck: venv
	$(BIN)/mypy

bench: venv
	$(BIN)/lumpbeam bench --json results/bench.json

clean:
	rm -rf $(VENV) .cache results build install log *.egg-info
