# Every target sets itself up: the first run creates .venv with Blender's bpy module and the dev tools.
PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed-$(shell cksum < requirements-dev.txt | cut -d' ' -f1)
VERSION := $(shell sed -n 's/^version = "\(.*\)"/\1/p' blender_manifest.toml)
ZIP := dist/ellimann-$(VERSION).zip
EXT_TOOL = $(VENV)/lib/python3.11/site-packages/bpy/5.0/scripts/addons_core/bl_pkg/cli/blender_ext.py
DEMO_OUT ?= out/demo

.PHONY: setup test demo build bench lint clean

setup: $(STAMP)

$(STAMP): requirements-dev.txt
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet -r requirements-dev.txt
	rm -f $(VENV)/.installed-*
	touch $@

test: $(STAMP)
	$(PY) -m pytest

demo: $(STAMP)
	$(PY) -m ellimann_addon demo -o $(DEMO_OUT)

build: $(STAMP)
	mkdir -p dist
	$(PY) $(EXT_TOOL) build --source-dir . --output-filepath $(ZIP)
	$(PY) $(EXT_TOOL) validate $(ZIP)

bench: $(STAMP)
	$(PY) -m bench

lint: $(STAMP)
	$(VENV)/bin/ruff check .

clean:
	rm -rf dist out .pytest_cache .ruff_cache
