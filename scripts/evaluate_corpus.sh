#!/usr/bin/env bash
# roar, CGAL alpha wrap + QEM and Manifold + QEM over the corpus manifest at each face budget,
# every output measured by `roar eval --ref RAW_INPUT`; writes DIR/table.md, DIR/results.json
# and DIR/models.tsv. Rerunning the same command resumes where a stopped run left off.
# How to run it and read the table: docs/evaluation.md, "Dataset table".
#
#   scripts/evaluate_corpus.sh [--manifest PATH] [--subset scripts/corpus-subset-50.tsv]
#       [--ids "ID ..."] [--limit K] [--budgets "500 1000 5000 10000"]
#       [--methods "roar alphawrap+qem manifold+qem"] [--out DIR] [--timeout SECONDS]
#       [--jobs J] [--samples S] [--measure-with ROAR] [--retry-failed] [--no-run]
#       [--paired OLD_ROAR NEW_ROAR]
#
# Default manifest: $ROAR_TEST_DATA/../corpus/manifest.tsv (ROAR_TEST_DATA: ../shared/data/meshes
# beside the repo). Default DIR: target/corpus-eval. The peers run in the virtualenv
# target/eval-venv (scripts/eval_venv.sh makes it on first use).
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$(pwd)"

for arg in "$@"; do
  case "$arg" in
    -h|--help) sed -n '2,15p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  esac
done

if [ -z "${ROAR_TEST_DATA:-}" ]; then
  ROAR_TEST_DATA="$(cd "$repo/../shared/data/meshes" 2>/dev/null && pwd || true)"
fi
manifest="${ROAR_TEST_DATA:-$repo/../shared/data/meshes}/../corpus/manifest.tsv"

echo "== building roar (release)" >&2
cargo build --release -q -p roar-cli
roar="${CARGO_TARGET_DIR:-$repo/target}/release/roar"

paired=false
for arg in "$@"; do
  [ "$arg" = "--paired" ] && paired=true
done
if $paired; then
  python=python3          # two roar binaries only: no peers, no virtualenv
else
  python="$(scripts/eval_venv.sh)"
fi

# The caller's flags come last, so its --manifest replaces the default.
exec "$python" "$repo/scripts/evaluate_corpus.py" --roar "$roar" --python "$python" \
  --manifest "$manifest" "$@"
