# Every target CI uses is here; .ci/run calls `make test`.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
SPEC ?= specs/my_robot.yaml

.PHONY: spec-docs install install-dev sysdeps demo test lint bench native native-check fuzz clean

# Two installs: `install` (make demo) is armcli and its runtime dependencies, with the compiled
# rollout (armcli.sim._rollout, CMakeLists.txt) built in; `install-dev` (make test, lint,
# bench) adds the dev extra's tools without rebuilding armcli. A change to pyproject.toml or
# the engine's C++/build files reinstalls. Both print their steps and, while pip is silent
# (the compile), a heartbeat every 30 s (scripts/install.sh).
STAMP := $(VENV)/.installed-stamp
DEV_STAMP := $(VENV)/.dev-stamp
$(STAMP): pyproject.toml CMakeLists.txt src/armcli/sim/_native/rollout.cpp $(wildcard src/armcli/plan/_native/*)
	@bash scripts/install.sh runtime $(PY) $(VENV)
	touch $(STAMP)

$(DEV_STAMP): $(STAMP) pyproject.toml
	@bash scripts/install.sh dev $(VENV)
	touch $(DEV_STAMP)

install: $(STAMP)
install-dev: $(DEV_STAMP)

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
	mkdir -p $(DEMO)
	$(BIN)/armcli simulate $(SPEC) --trajectory specs/trajectories/pick.yaml \
	  --output $(DEMO)/states.csv --plot $(DEMO)/tracking.png
	$(BIN)/armcli render $(SPEC) --pose reach -o $(DEMO)/robot.png
	$(BIN)/armcli ros-package $(SPEC) -o $(DEMO)/ros
	@echo "demo: outputs in urdf/ and $(DEMO)/"

lint: install-dev
	$(BIN)/ruff check src tests bench
	$(BIN)/ruff format --check src tests bench
	$(BIN)/mypy src tests

# The suite in two timed runs: everything but the `slow` tests, and alongside it (on the
# other core: mostly pip and one compile waiting) the `slow` ones (installs into fresh
# virtualenvs, pre-commit), their output in out/test-slow.log, printed after. Each prints
# its own time and slowest tests; either failing fails `make test`.
SLOW_LOG := out/test-slow.log
test: install-dev sysdeps lint native-check
	$(BIN)/armcli build --check $(SPEC)
	@mkdir -p out
	@echo "test: the slow tests run alongside; their output follows the others' ($(SLOW_LOG))"
	@$(BIN)/python -m pytest -q -m slow --durations=10 -p no:cacheprovider >$(SLOW_LOG) 2>&1 & \
	  slow=$$!; trap 'kill $$slow 2>/dev/null; exit 130' INT TERM; \
	  $(BIN)/python -m pytest -q -m "not slow" --durations=10; fast_rc=$$?; \
	  wait $$slow; slow_rc=$$?; \
	  echo "test: the slow tests (-m slow), run alongside:"; cat $(SLOW_LOG); \
	  echo "test: not slow exit $$fast_rc, slow exit $$slow_rc"; \
	  [ $$fast_rc -eq 0 ] && [ $$slow_rc -eq 0 ]

# Rebuild the compiled rollout after editing its C++ (the editable install does not rebuild
# on import): incremental, in build/, with the build tools of the dev extra. Not through the
# install stamp, which a C++ edit outdates: that would recreate the whole venv.
native:
	@test -x $(BIN)/python || $(MAKE) install-dev
	@echo "native: recompiling the engine, the drive steps and the planner (armcli.sim._rollout, armcli.sim._drivestep, armcli.plan._planner)"
	$(BIN)/python -m pip install -q --no-build-isolation --no-deps -e .
	$(BIN)/python -m armcli.sim.native
	$(BIN)/python -m armcli.drive.step
	$(BIN)/python -m armcli.plan.native

# The compiled engine must be there wherever a C++ compiler exists: a failed build fails
# `make test` instead of skipping its tests.
native-check: install-dev
	@if command -v c++ >/dev/null 2>&1 || command -v g++ >/dev/null 2>&1; then \
	  $(BIN)/python -m armcli.sim.native && $(BIN)/python -m armcli.drive.step && \
	  $(BIN)/python -m armcli.plan.native; \
	else echo "no C++ compiler: armcli installs without its simulator; simulator tests skip"; fi

bench: install-dev native-check
	$(BIN)/python bench/bench_sim.py
	$(BIN)/python bench/bench_process.py
	$(BIN)/python bench/bench_tune.py
	$(BIN)/python bench/bench_check_dof.py
	$(BIN)/python bench/bench_plan.py
	$(BIN)/python bench/bench_place.py
	$(BIN)/python bench/bench_first_hour.py
	$(BIN)/python bench/bench_check_corpus.py
	$(BIN)/python bench/bench_check_packages.py
	$(BIN)/python bench/bench_build_expand.py
	$(BIN)/python bench/bench_drive.py
	$(BIN)/python bench/bench_sensors.py

fuzz: install-dev
	HYPOTHESIS_PROFILE=fuzz $(BIN)/python -m pytest -q tests -k fuzz

clean:
	rm -rf $(VENV) build dist out .pytest_cache .ruff_cache .mypy_cache

# The spec reference is generated from the pydantic models (a test keeps it in sync).
spec-docs: install-dev
	$(BIN)/python -m armcli.spec.reference > docs/spec.md
