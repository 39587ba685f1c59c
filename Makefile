# `make demo` and `make test` each set everything up on a fresh machine and run.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test setup system-deps bench docs clean wheel-check


demo: setup
	$(BIN)/delve demo

# The tests run on every core (at most 4), a test file per worker: its module fixtures
# (a scenario run several tests read) then run once.
test: setup
	$(BIN)/python -m pytest -n auto --maxprocesses 4 --dist loadfile

setup: system-deps $(STAMP)

# open3d cannot be imported without libusb-1.0; tree .svg dumps need graphviz's `dot`.
system-deps:
	@missing=""; \
	ldconfig -p | grep -q 'libusb-1.0.so.0' || missing="$$missing libusb-1.0-0"; \
	command -v dot >/dev/null 2>&1 || missing="$$missing graphviz"; \
	if [ -n "$$missing" ]; then \
	  echo "installing system packages:$$missing"; \
	  SUDO=""; [ "$$(id -u)" -ne 0 ] && SUDO=sudo; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $$missing; \
	fi

$(VENV)/bin/python:
	$(PYTHON) -m venv $(VENV)

$(STAMP): $(VENV)/bin/python pyproject.toml
	$(BIN)/pip install -q --upgrade pip
	# The editable install's note about same-named folders is the only thing it would print.
	PYTHONWARNINGS="ignore:Editable installation" $(BIN)/pip install -q -e '.[test]'
	touch $(STAMP)

bench: setup
	$(BIN)/python bench/sim_speed.py
	$(BIN)/python bench/bt_overhead.py
	$(BIN)/python bench/gbplanner.py
	$(BIN)/python bench/hot_paths.py

# Regenerate the tree JSON Schema and docs/nodes.md from the node registry, into this
# source tree (the generator writes only where it is told, never into site-packages).
docs: setup
	$(BIN)/python -m delve.executive.generate --schema-dir executive/schema --docs docs/nodes.md

# Build the wheel, install it into a fresh venv and run it from an empty folder:
# the shipped trees and scenarios validate, and the demo runs.
WHEEL_TMP := $(shell mktemp -d -u /tmp/delve-wheel-XXXXXX)
wheel-check: system-deps
	$(PYTHON) -m venv $(WHEEL_TMP)/venv
	$(WHEEL_TMP)/venv/bin/pip install -q --upgrade pip
	$(WHEEL_TMP)/venv/bin/pip wheel -q --no-deps -w $(WHEEL_TMP)/dist .
	rm -rf build
	$(WHEEL_TMP)/venv/bin/pip install -q $(WHEEL_TMP)/dist/delve-*.whl
	mkdir -p $(WHEEL_TMP)/empty
	cd $(WHEEL_TMP)/empty && $(WHEEL_TMP)/venv/bin/delve validate --shipped >/dev/null
	cd $(WHEEL_TMP)/empty && $(WHEEL_TMP)/venv/bin/delve demo --quiet
	test -s $(WHEEL_TMP)/empty/delve-out/demo/report.json
	rm -rf $(WHEEL_TMP)

clean:
	rm -rf $(VENV) delve-out .pytest_cache build
