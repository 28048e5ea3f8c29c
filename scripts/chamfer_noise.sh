#!/usr/bin/env bash
# Seed-to-seed noise of the two Chamfer measures of `roar eval`: for each MESH:REF pair, runs
# `roar eval MESH --ref REF --json --seed K` for every seed and prints a markdown table of the
# sampled (`chamfer_l2_over_diag`) and exact (`chamfer_exact_over_diag`) values: their mean and
# their relative spread (max − min) / mean.
#
#   scripts/chamfer_noise.sh [--samples S] [--seeds "0 1 2 3 4"] MESH:REF ...
#
# Uses $ROAR if set, else target/release/roar (build it with `cargo build --release -p roar-cli`).
# --samples defaults to roar eval's own default. Needs jq.
set -euo pipefail
cd "$(dirname "$0")/.."

roar="${ROAR:-target/release/roar}"
samples=()
seeds="0 1 2 3 4"

usage() { sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; }
while [ $# -gt 0 ]; do
  case "$1" in
    --samples) samples=(--samples "$2"); shift 2 ;;
    --seeds) seeds="$2"; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    --*) echo "unknown option $1" >&2; usage >&2; exit 2 ;;
    *) break ;;
  esac
done
[ $# -gt 0 ] || { usage >&2; exit 2; }

# mean and (max - min) / mean of the numbers on stdin, one a line
stats() { awk 'NR == 1 { lo = $1; hi = $1 } { s += $1; if ($1 < lo) lo = $1; if ($1 > hi) hi = $1 }
  END { m = s / NR; if (m > 1e-12) printf "%.4e | %.2f %%", m, 100 * (hi - lo) / m; else printf "%.1e | –", m }'; }

echo "| mesh vs reference | sampled Chamfer/diag | spread | exact Chamfer/diag | spread | seconds per eval |"
echo "|---|---:|---:|---:|---:|---:|"
for pair in "$@"; do
  mesh="${pair%%:*}"
  ref="${pair#*:}"
  sampled=""
  exact=""
  start=$(date +%s.%N)
  runs=0
  for seed in $seeds; do
    json=$("$roar" eval "$mesh" --ref "$ref" --json --seed "$seed" "${samples[@]}")
    sampled+="$(jq '.fidelity.chamfer_l2_over_diag' <<<"$json")"$'\n'
    exact+="$(jq '.fidelity.chamfer_exact_over_diag' <<<"$json")"$'\n'
    runs=$((runs + 1))
  done
  seconds=$(echo "$start $(date +%s.%N) $runs" | awk '{ printf "%.1f", ($2 - $1) / $3 }')
  echo "| $(basename "$mesh") vs $(basename "$ref") | $(printf %s "$sampled" | stats) | $(printf %s "$exact" | stats) | $seconds |"
done
