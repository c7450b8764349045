# The two commands a newcomer needs: `make demo` and `make test`.
# Both create .venv on first use and install the package with every extra from PyPI
# (requirements.txt); `make test` adds the development tools (requirements-dev.txt).
# Nothing is cached outside this folder: pip, matplotlib and ROS logs live under .cache/.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
DEV_STAMP := $(VENV)/.dev-installed-stamp

export PIP_CACHE_DIR := $(CURDIR)/.cache/pip
export MPLCONFIGDIR := $(CURDIR)/.cache/matplotlib
export MPLBACKEND := Agg
export ROS_LOG_DIR := $(CURDIR)/.cache/ros/log
export ROS_HOME := $(CURDIR)/.cache/ros
export ROS_AUTOMATIC_DISCOVERY_RANGE ?= LOCALHOST
export PYTHONDONTWRITEBYTECODE :=

.PHONY: venv dev demo test test-opencv-lowest test-slow fuzz lint typecheck bench docs clean

# One pip run: the venv's own pip installs these wheels as well as a newer one would, so it
# is not upgraded first (about 5 s). --no-compile: Python compiles a module when it is first
# imported instead of pip compiling all ~6000 files of the dependencies up front (~28 s of
# CPU), most of which nothing here imports.
$(STAMP): setup.py setup.cfg package.xml requirements.txt
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --disable-pip-version-check --no-compile -r requirements.txt
	@touch $@

# The tests, lint, types, the docs site and the lab's peers (MuJoCo, pyyeti), on top.
$(DEV_STAMP): $(STAMP) requirements-dev.txt
	$(BIN)/python -m pip install -q --disable-pip-version-check --no-compile -r requirements-dev.txt
	@touch $@

venv: $(STAMP)

dev: $(DEV_STAMP)

demo: venv
	$(BIN)/lumpbeam demo --out results

# The suite mostly waits (ROS discovery, child processes), so it runs in parallel workers
# (pytest-xdist), one per core and at most 4. Each ROS test claims a domain no other worker
# holds (test/harness.py). A test module goes to one worker whole (loadscope), so a costly
# module fixture is built once. PYTEST_WORKERS=0 runs everything in this process.
PYTEST_WORKERS ?= auto
PYTEST_PARALLEL := -n $(PYTEST_WORKERS) --maxprocesses=4 --dist loadscope

# The lowest OpenCV setup.py accepts (its [vision] lower bound): the venv holds the newest,
# and the tests that use OpenCV run again on this one, installed alone into .cache and put
# first on the path.
OPENCV_LOWEST := $(shell sed -n "s/.*'opencv-python-headless>=\([0-9.]*\),.*/\1/p" setup.py)
OPENCV_LOWEST_DIR := .cache/opencv-$(OPENCV_LOWEST)
OPENCV_TESTS := test/core/vision test/apps/cli/test_track.py test/apps/cli/test_track_sources.py \
	test/test_calibrate_real_photos.py test/test_setup.py::test_opencv_is_within_the_declared_range

$(OPENCV_LOWEST_DIR)/.stamp: setup.py
	$(BIN)/python -m pip install -q --disable-pip-version-check --no-compile --no-deps \
		--target $(OPENCV_LOWEST_DIR) 'opencv-python-headless==$(OPENCV_LOWEST).*'
	@touch $@

test-opencv-lowest: dev $(OPENCV_LOWEST_DIR)/.stamp
	PYTHONPATH=$(OPENCV_LOWEST_DIR) $(BIN)/python -m pytest $(PYTEST_PARALLEL) -m 'not slow' \
		-p no:cacheprovider $(OPENCV_TESTS)

# pytest also builds the documentation site (mkdocs build --strict) and checks its links
# (test/test_docs.py).
test: dev
	$(BIN)/ruff check .
	$(BIN)/mypy
	$(BIN)/python -m pytest $(PYTEST_PARALLEL)
	$(MAKE) --no-print-directory test-opencv-lowest

# The long validation matrices (marked slow): CI runs them after `make test`. The computing
# ones run in parallel; the live graphs among them (marked ros) then run alone, on a machine
# no other worker keeps busy (best-effort camera frames, replays at their rate).
test-slow: dev
	$(BIN)/python -m pytest $(PYTEST_PARALLEL) -m 'slow and not ros'
	$(BIN)/python -m pytest -m 'slow and ros'

# The fuzz campaign at length: random damage to product-written bags through the readers,
# doctor, repair, analyze, diagnose and track, spoiled /tip_pose and /tip_load streams through
# analyze and diagnose (test/core/bagio/test_fuzz.py), and random messages into the nodes'
# callbacks (test/nodes/test_fuzz_callbacks.py) and property-based ones on their topics
# (test/nodes/test_fuzz_topics.py, hypothesis). make test runs them at 200 cases.
FUZZ_CASES ?= 5000
fuzz: dev
	LUMPBEAM_FUZZ_CASES=$(FUZZ_CASES) $(BIN)/python -m pytest test/core/bagio/test_fuzz.py \
		test/nodes/test_fuzz_callbacks.py test/nodes/test_fuzz_topics.py -n0 -q -p no:logging -s

lint: dev
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

# Strict static types of the ROS-free core (the module list is in mypy.ini).
typecheck: dev
	$(BIN)/mypy

bench: dev
	$(BIN)/lumpbeam bench --json results/bench.json

# The documentation site (mkdocs.yml): the README, the pages under doc/ and the API reference
# from the docstrings, into site/. `make test` builds it too, with warnings as errors, and
# checks its internal links (test/test_docs.py).
docs: dev
	$(BIN)/mkdocs build --strict --site-dir site

clean:
	rm -rf $(VENV) .cache results build install log site *.egg-info
