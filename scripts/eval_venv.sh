#!/usr/bin/env bash
# Prints the python of the virtualenv target/eval-venv, first making it and installing the
# evaluation's peers (pymeshlab, point-cloud-utils, numpy, scipy, trimesh) if it lacks them.
# Used by scripts/evaluate.sh, scripts/compare_scans.sh and scripts/evaluate_sdf.sh --meshlab.
set -euo pipefail
cd "$(dirname "$0")/.."
venv="$(pwd)/target/eval-venv"
if ! "$venv/bin/python" -c "import pymeshlab, point_cloud_utils, numpy, scipy, trimesh" 2>/dev/null; then
  echo "== installing the peers into $venv (once; about 2 minutes)" >&2
  python3 -m venv "$venv"
  "$venv/bin/pip" install -q --disable-pip-version-check pymeshlab point-cloud-utils numpy scipy trimesh >&2
fi
echo "$venv/bin/python"
