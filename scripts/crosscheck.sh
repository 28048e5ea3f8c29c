#!/usr/bin/env bash
# Cross-checks roar's evaluation metrics against trimesh, MeshLab (pymeshlab) and scipy on the
# shared test meshes; see scripts/crosscheck.py for what is compared and the tolerances.
# Needs ROAR_TEST_DATA (the folder holding clean/ and wild/). Creates (or reuses) a virtualenv in
# target/crosscheck-venv. Usage: scripts/crosscheck.sh [ROAR] (default: a release build made
# here). Exits non-zero on any disagreement beyond tolerance.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ -z "${ROAR_TEST_DATA:-}" ]; then
  echo "crosscheck: ROAR_TEST_DATA is not set (it must name the folder with clean/ and wild/)" >&2
  exit 2
fi
for d in clean wild; do
  if [ ! -d "$ROAR_TEST_DATA/$d" ]; then
    echo "crosscheck: missing folder $ROAR_TEST_DATA/$d" >&2
    exit 2
  fi
done

venv=target/crosscheck-venv
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c "import trimesh, numpy, scipy, pymeshlab" 2>/dev/null; then
  echo "crosscheck: setting up $venv (trimesh, numpy, scipy, pymeshlab)"
  python3 -m venv "$venv" || { echo "crosscheck: python3 -m venv failed" >&2; exit 2; }
  "$venv/bin/pip" install --quiet --upgrade pip
  "$venv/bin/pip" install --quiet trimesh numpy scipy pymeshlab \
    || { echo "crosscheck: pip install failed" >&2; exit 2; }
fi

# The evaluator: `roar eval --json` of the binary given as the first argument, or of a release
# build made here.
if [ -n "${1:-}" ]; then
  cmd=("$1" eval --json)
else
  echo "crosscheck: building the evaluator (release)"
  cargo build --release --quiet -p roar-cli
  cmd=(target/release/roar eval --json)
fi
echo "crosscheck: evaluator: ${cmd[*]}"

"$venv/bin/python" scripts/crosscheck.py "$ROAR_TEST_DATA" "${cmd[@]}"
