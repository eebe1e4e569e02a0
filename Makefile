# Every target CI uses is here; .ci/run calls `make test`.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp
SPEC ?= specs/my_robot.yaml

.PHONY: spec-docs install sysdeps demo test lint bench native native-or-skip fuzz clean

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

DEMO := out/demo

# The main job on the default spec: build, lint the model, simulate a pick motion, render,
# and generate the ROS 2 / MoveIt packages. Outputs land in out/demo/.
demo: install
	$(BIN)/armcli build $(SPEC)
	$(BIN)/armcli check $(SPEC)
	$(BIN)/armcli simulate $(SPEC) --trajectory specs/trajectories/pick.yaml \
	  --output $(DEMO)/states.csv --plot $(DEMO)/tracking.png
	$(BIN)/armcli render $(SPEC) --pose reach -o $(DEMO)/robot.png
	$(BIN)/armcli ros-package $(SPEC) -o $(DEMO)/ros
	@echo "demo: outputs in urdf/ and $(DEMO)/"

lint: install
	$(BIN)/ruff check src tests bench
	$(BIN)/ruff format --check src tests bench
	$(BIN)/mypy src

test: install sysdeps lint native-or-skip
	$(BIN)/armcli build --check $(SPEC)
	$(BIN)/python -m pytest -q

# Compiled simulator rollout (optional: armcli falls back to its Python loop). Cached under
# ~/.cache/armcli/native keyed by source + pin version; ~2-4 min the first time.
native: install
	$(BIN)/python -m armcli.sim.native

# For the tests: build the compiled path when possible; its tests skip (with the reason)
# where no compiler is available, and everything else uses the Python loop.
native-or-skip: install
	@$(BIN)/python -m armcli.sim.native || echo "native rollout not built; its tests will skip"

bench: install native
	$(BIN)/python bench/bench_sim.py
	$(BIN)/python bench/bench_tune.py

fuzz: install
	HYPOTHESIS_PROFILE=fuzz $(BIN)/python -m pytest -q tests -k fuzz

clean:
	rm -rf $(VENV) build dist out .pytest_cache .ruff_cache .mypy_cache

# The spec reference is generated from the pydantic models (a test keeps it in sync).
spec-docs: install
	$(BIN)/python -m armcli.spec.reference > docs/spec.md
