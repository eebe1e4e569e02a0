# Every target CI uses is here; .ci/run calls `make test`.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
SPEC ?= specs/my_robot.yaml

.PHONY: install sysdeps demo test lint bench native fuzz clean

$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -e '.[dev]'
	touch $(STAMP)

install: $(STAMP)

# Debian tools some tests use (check_urdf, headless Chromium). Tests skip with a
# reason where these cannot be installed (no apt, not root).
sysdeps:
	@bash scripts/sysdeps.sh

demo: install
	$(BIN)/armcli build $(SPEC)
	@echo "demo: build done"

lint: install
	$(BIN)/ruff check src tests bench
	$(BIN)/ruff format --check src tests bench

test: install sysdeps lint
	$(BIN)/armcli build --check $(SPEC)
	$(BIN)/python -m pytest -q

# Compiled simulator rollout (optional: armcli falls back to its Python loop). Cached under
# ~/.cache/armcli/native keyed by source + pin version; ~2-4 min the first time.
native: install
	$(BIN)/python -m armcli.native

bench: install native
	$(BIN)/python bench/bench_sim.py

fuzz: install
	HYPOTHESIS_PROFILE=fuzz $(BIN)/python -m pytest -q tests -k fuzz

clean:
	rm -rf $(VENV) build dist .pytest_cache .ruff_cache .mypy_cache
