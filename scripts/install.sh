#!/usr/bin/env bash
# The two installs of the Makefile, with a heartbeat so a long step is visibly working.
#   install.sh runtime PY VENV   venv + armcli and its runtime dependencies (compiles the engine)
#   install.sh dev VENV          the dev extra's tools (tests, lint, benchmarks) into that venv
set -euo pipefail
kind=$1

# Run a command; while it runs, say every 30 s that it still does (pip is silent while a
# C++ extension compiles).
with_heartbeat() {
  local label=$1; shift
  "$@" &
  local pid=$! start=$SECONDS
  while kill -0 "$pid" 2>/dev/null; do
    sleep 1
    if (( (SECONDS - start) % 30 == 0 && SECONDS > start )); then
      echo "install: $label, still working ($(( (SECONDS - start) / 60 )) min $(( (SECONDS - start) % 60 )) s)"
    fi
  done
  wait "$pid"
}

case $kind in
  runtime)
    py=$2 venv=$3
    echo "install [1/3]: virtual environment in $venv"
    "$py" -m venv "$venv"
    echo "install [2/3]: pip"
    "$venv/bin/python" -m pip install -q --upgrade pip
    echo "install [3/3]: armcli and its runtime dependencies, compiling the engine (the longest step)"
    with_heartbeat "armcli" "$venv/bin/python" -m pip install --progress-bar off -e .
    ;;
  dev)
    venv=$2
    echo "install [dev]: test, lint and benchmark tools (the dev extra of pyproject.toml)"
    reqs=$(mktemp)
    trap 'rm -f "$reqs"' EXIT
    "$venv/bin/python" scripts/extra_requirements.py dev >"$reqs"
    with_heartbeat "dev tools" "$venv/bin/python" -m pip install --progress-bar off -r "$reqs"
    ;;
  *) echo "usage: install.sh runtime PY VENV | dev VENV" >&2; exit 2 ;;
esac
echo "install: done"
