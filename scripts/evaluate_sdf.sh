#!/usr/bin/env bash
# roar against the marching baseline on SDF inputs (docs/sdf.md): for each field, roar at every
# budget and, at every grid resolution, `roar extract` (marching tetrahedra) decimated to the
# budget by `roar decimate` (roar's QEM). Every output is measured by `roar eval --ref` against
# the reference surface, the marching extraction of the same field at the reference resolution;
# the table gives the field's evaluations (values and gradients), seconds, peak memory, the
# floor-free Chamfer/diag and normal cosine (exact closest points), and the sampled Chamfer/diag
# beside it. Writes DIR/table.md and DIR/results.json.
#
#   scripts/evaluate_sdf.sh [--fields "A.npz B.npz"] [--budgets "5000 50000"]
#       [--resolutions "32 64 128 256 512"] [--reference 512] [--samples 1000000] [--config FILE]
#       [--refs "A.obj B.obj"] [--meshlab] [--out DIR]
#
# Defaults: the two shared networks (../shared/data/sdf/nif-bunny.npz, nif-hammer.npz), budgets
# 5000 and 50000, resolutions 32 to 512, reference 512, 1,000,000 samples per side for Chamfer (at
# 50,000 faces 200,000 samples put a floor under the figures that hides the differences), DIR
# target/evaluate-sdf; roar with the SDF schedule's defaults unless --config gives a file of
# overrides. --refs gives one reference mesh per field instead of the extraction (a grid of a
# mesh's exact distance, scripts/mesh_sdf_grid.py, against that mesh). Extractions are kept
# (MESH.obj.json) and roar runs resumed. Needs python3 (no packages).
# --meshlab adds, for every extraction, rows decimated by MeshLab's QEM instead of roar's
# (scripts/peers.py qem, in the virtualenv target/eval-venv that scripts/eval_venv.sh makes).
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$(pwd)"

data="${ROAR_SDF_DATA:-$repo/../shared/data/sdf}"
fields="$data/nif-bunny.npz $data/nif-hammer.npz"
budgets="5000 50000"
resolutions="32 64 128 256 512"
reference=512
samples=1000000
config=""
refs=""
meshlab=""
out="target/evaluate-sdf"
while [ $# -gt 0 ]; do
  case "$1" in
    --fields) fields="$2"; shift 2 ;;
    --budgets) budgets="$2"; shift 2 ;;
    --resolutions) resolutions="$2"; shift 2 ;;
    --reference) reference="$2"; shift 2 ;;
    --samples) samples="$2"; shift 2 ;;
    --config) config="$2"; shift 2 ;;
    --refs) refs="$2"; shift 2 ;;
    --meshlab) meshlab=1; shift ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "evaluate_sdf.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
for f in $fields; do
  if [ ! -f "$f" ]; then
    echo "evaluate_sdf.sh: no SDF at '$f' (--fields, or set ROAR_SDF_DATA)" >&2
    exit 2
  fi
done

python_args=()
if [ -n "$meshlab" ]; then
  python_args=(--meshlab "$(scripts/eval_venv.sh)")
fi
if [ -n "$refs" ]; then
  python_args+=(--refs $refs)
fi

echo "== building roar (release)" >&2
cargo build --release -q -p roar-cli
mkdir -p "$out"
exec python3 "$repo/scripts/evaluate_sdf.py" --roar "$repo/target/release/roar" --fields $fields \
  --budgets $budgets --resolutions $resolutions --reference "$reference" --samples "$samples" --config "$config" \
  "${python_args[@]}" --out "$out"
