# Every target sets itself up. The working venv .venv is the matrix's Blender 5.0 lane (bpy 5.0.1,
# Python 3.11); `make test` also makes the other lanes' venvs (.venv-bpy4.2, .venv-bpy4.5,
# .venv-bpy5.3) on first use. tools/matrix/lanes.py says which Blender, Python and numpy each one holds.
PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
VERSION := $(shell sed -n 's/^version = "\(.*\)"/\1/p' blender_manifest.toml)
ZIP := dist/ellimann-$(VERSION).zip
EXT_TOOL = $(VENV)/lib/python3.11/site-packages/bpy/5.0/scripts/addons_core/bl_pkg/cli/blender_ext.py
DEMO_OUT ?= out/demo
# make test LANES=4.2,5.3 runs some lanes only
LANES ?=

.PHONY: setup test check demo build bench lint clean

setup:
	@$(PYTHON) -m tools.matrix --setup-only --lanes 5.0

# The whole matrix: Blender 4.2, 4.5, 5.0 and 5.3 (what CI runs).
test:
	$(PYTHON) -m tools.matrix --lanes "$(LANES)"

# The fast lane for working: core, command-line and Blender tests not marked slow, on the working venv.
check: setup
	$(PY) -m pytest -p no:cacheprovider -q -m "not slow" tests/core tests/cli tests/blender

demo: setup
	$(PY) -m ellimann_addon demo -o $(DEMO_OUT)

build: setup
	mkdir -p dist
	$(PY) $(EXT_TOOL) build --source-dir . --output-filepath $(ZIP)
	$(PY) $(EXT_TOOL) validate $(ZIP)

bench: setup
	$(PY) -m bench

lint: setup
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

clean:
	rm -rf dist out .pytest_cache .ruff_cache
