#!/usr/bin/env bash
# roar against Screened Poisson + QEM and alpha wrap + QEM on a range-scan set (docs/scans.md):
# each at every budget, measured by `roar eval --ref REFERENCE`, with seconds and peak memory;
# plus the reference itself decimated by QEM (the floor: not a reconstruction from the scans).
# Writes DIR/table.md and DIR/results.json.
#
#   scripts/compare_scans.sh [--set SET.conf] [--ref REFERENCE] [--budgets "1000 5000"] [--out DIR]
#
# Defaults: the Stanford bunny beside the repo (../shared/data/scans/stanford-bunny/bun.conf and
# its bun_zipper.ply), budgets 1000 and 5000, DIR target/compare-scans. The peers run on the
# aligned patches `roar scans` writes (the same poses roar reconstructs from). PyMeshLab goes into
# the virtualenv target/eval-venv (scripts/eval_venv.sh), made on first use.
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$(pwd)"

set_path="$repo/../shared/data/scans/stanford-bunny/bun.conf"
ref=""
budgets="1000 5000"
out="target/compare-scans"
while [ $# -gt 0 ]; do
  case "$1" in
    --set) set_path="$2"; shift 2 ;;
    --ref) ref="$2"; shift 2 ;;
    --budgets) budgets="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "compare_scans.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
if [ ! -e "$set_path" ]; then
  echo "compare_scans.sh: no scan set at '$set_path' (--set)" >&2
  exit 2
fi
if [ -z "$ref" ]; then
  ref="$(dirname "$set_path")/bun_zipper.ply"
fi
if [ ! -f "$ref" ]; then
  echo "compare_scans.sh: no reference mesh at '$ref' (--ref)" >&2
  exit 2
fi

echo "== building roar (release)" >&2
cargo build --release -q -p roar-cli
roar="$repo/target/release/roar"

python="$(scripts/eval_venv.sh)"

mkdir -p "$out"
exec "$python" "$repo/scripts/compare_scans.py" --roar "$roar" --set "$set_path" \
  --ref "$ref" --budgets $budgets --out "$out" --peers "$repo/scripts/peers.py"
