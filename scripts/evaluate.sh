#!/usr/bin/env bash
# roar vs its peers on the wild meshes: reconstructs every mesh at each face budget with roar,
# roar's own init + QEM, CGAL alpha wrap + QEM and Manifold + QEM, measures all of them with
# `roar eval --ref RAW_INPUT`, and writes DIR/table.md and DIR/results.json.
# How to run it and read the table: docs/evaluation.md.
#
#   scripts/evaluate.sh [--budgets "1000 5000"] [--meshes "GLOB ..."] [--iterations K] [--out DIR]
#                       [--samples S] [--timeout SECONDS] [--methods "roar roar-init+qem ..."]
#                       [--keep-from DIR ...]
#
# Inputs: $ROAR_TEST_DATA/wild (default ROAR_TEST_DATA: ../shared/data/meshes beside the repo).
# The peers (pymeshlab, point-cloud-utils) go into the virtualenv target/eval-venv, made on first
# use and reused afterwards. A full default run takes hours on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$(pwd)"

budgets="1000 5000"
meshes="*"
iterations=""
out="target/evaluation"
samples=50000
timeout=3600
methods="roar roar-init+qem alphawrap+qem manifold+qem"
keep_from=()

usage() { sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; }
while [ $# -gt 0 ]; do
  case "$1" in
    --budgets) budgets="$2"; shift 2 ;;
    --meshes) meshes="$2"; shift 2 ;;
    --iterations) iterations="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --samples) samples="$2"; shift 2 ;;
    --timeout) timeout="$2"; shift 2 ;;
    --methods) methods="$2"; shift 2 ;;
    --keep-from) keep_from+=(--keep-from "$2"); shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "evaluate.sh: unknown argument $1" >&2; usage >&2; exit 2 ;;
  esac
done

if [ -z "${ROAR_TEST_DATA:-}" ]; then
  ROAR_TEST_DATA="$(cd "$repo/../shared/data/meshes" 2>/dev/null && pwd || true)"
fi
data="${ROAR_TEST_DATA:-}/wild"
if [ ! -d "$data" ]; then
  echo "evaluate.sh: no wild meshes at '$data' (set ROAR_TEST_DATA)" >&2
  exit 2
fi

echo "== building roar (release)" >&2
cargo build --release -q -p roar-cli
roar="$repo/target/release/roar"

python="$(scripts/eval_venv.sh)"

mkdir -p "$out"
args=(--roar "$roar" --python "$python" --data "$data" --meshes "$meshes"
      --budgets "$budgets" --samples "$samples" --timeout "$timeout" --methods "$methods"
      --out "$out")
args+=("${keep_from[@]}")
if [ -n "$iterations" ]; then
  args+=(--iterations "$iterations")
fi
exec "$python" "$repo/scripts/evaluate.py" "${args[@]}"
