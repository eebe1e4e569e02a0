#!/usr/bin/env bash
# The GitHub Action's step (action.yml): run `armcli check` on INPUT_PATHS, print GitHub
# workflow annotations (::error file=...,line=...::), optionally write SARIF, and set the
# step outputs. Runs the same outside Actions: tests/adoption/test_action.py calls it
# with the environment an Action run gives it.
#
# Inputs (environment): INPUT_PATHS (space-separated, default "."), INPUT_STRICT
# (true/false), INPUT_SARIF_FILE (path or empty), INPUT_ARGS (extra arguments, split on
# whitespace). GITHUB_OUTPUT, when set, receives exit-code= and sarif-file=.
set -uo pipefail

# A workflow command's message: %, CR and LF escaped, so a value cannot start a command line.
esc() {
  local s=${1//'%'/%25}
  s=${s//$'\r'/%0D}
  printf '%s' "${s//$'\n'/%0A}"
}

die() {
  echo "::error title=armcli action::$(esc "$1")"
  exit 2
}

ARMCLI="${ARMCLI:-armcli}"
read -r -a paths <<<"${INPUT_PATHS:-.}"
[ "${#paths[@]}" -gt 0 ] || paths=(.)
read -r -a extra <<<"${INPUT_ARGS:-}"
case "${INPUT_STRICT:-false}" in
  true | True | TRUE) extra+=(--strict) ;;
  false | False | FALSE | "") ;;
  *) die "input 'strict' must be true or false, got '${INPUT_STRICT}'" ;;
esac

sarif="${INPUT_SARIF_FILE:-}"
if [ -n "$sarif" ]; then
  mkdir -p "$(dirname -- "$sarif")" || die "cannot create the directory of '$sarif'"
  tmp="$sarif.tmp.$$"
  "$ARMCLI" check --format sarif "${extra[@]}" -- "${paths[@]}" >"$tmp" 2>/dev/null
  sarif_code=$?
  if [ "$sarif_code" -le 2 ] && [ -s "$tmp" ]; then
    mv -- "$tmp" "$sarif"  # written whole or not at all
  else
    rm -f -- "$tmp"
    die "armcli could not write SARIF (exit $sarif_code)"
  fi
fi

# Annotations go to stdout, where the runner reads workflow commands; the one-line
# errors (unusable files, the total) go to stderr, into the log.
"$ARMCLI" check --format github "${extra[@]}" -- "${paths[@]}"
code=$?

if [ -n "${GITHUB_OUTPUT:-}" ]; then
  {
    echo "exit-code=$code"
    echo "sarif-file=$sarif"
  } >>"$GITHUB_OUTPUT"
fi
exit "$code"
