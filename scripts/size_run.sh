#!/usr/bin/env bash
# The size run: for each input size, generates a soup in a temporary folder and runs
# `roar reconstruct --faces BUDGET` on it with the release binary, one run at a time, printing a
# Markdown row per run: wall seconds and peak memory (/usr/bin/time -v) and the report's largest
# stages. Not part of CI.
#
#   scripts/size_run.sh [--soup torus|corpus] [--faces "100000 500000 1000000 2000000 5000000"]
#                       [--budget 5000] [--roar BINARY]
#
# torus: scripts/size_run.py, a rippled torus (one smooth closed surface, stored as a soup);
# corpus: scripts/scale_soup.py, 50 corpus models placed with overlapping random transforms
# (needs the evaluation virtualenv, scripts/eval_venv.sh). Default: both soups, the five sizes.
set -euo pipefail
cd "$(dirname "$0")/.."
soups="torus corpus"
sizes="100000 500000 1000000 2000000 5000000"
budget=5000
roar=""
while [ $# -gt 0 ]; do
  case "$1" in
    --soup) soups="$2"; shift 2 ;;
    --faces) sizes="$2"; shift 2 ;;
    --budget) budget="$2"; shift 2 ;;
    --roar) roar="$2"; shift 2 ;;
    -h|--help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "unknown argument: $1" >&2; exit 2 ;;
  esac
done
if [ -z "$roar" ]; then
  cargo build --release -q -p roar-cli
  roar="${CARGO_TARGET_DIR:-$PWD/target}/release/roar"
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

echo "| soup | input faces | seconds | peak GB | largest stages (s) |"
echo "|---|---:|---:|---:|---|"
for soup in $soups; do
  for faces in $sizes; do
    case "$soup" in
      torus) python3 scripts/size_run.py "$work/soup.stl" "$faces" > /dev/null ;;
      corpus) "$(scripts/eval_venv.sh)" scripts/scale_soup.py "$work/soup.stl" "$faces" > /dev/null ;;
      *) echo "unknown soup: $soup" >&2; exit 2 ;;
    esac
    if ! /usr/bin/time -v "$roar" reconstruct "$work/soup.stl" -o "$work/out.obj" \
        --faces "$budget" -q --report "$work/report.json" > /dev/null 2> "$work/time"; then
      echo "| $soup | $faces | failed: $(grep -m1 'roar' "$work/time" || tail -1 "$work/time") | | |"
      continue
    fi
    python3 - "$soup" "$faces" "$work/time" "$work/report.json" <<'EOF'
import json, re, sys
soup, faces, time_path, report_path = sys.argv[1:]
text = open(time_path).read()
wall = re.search(r"Elapsed \(wall clock\) time.*: (?:(\d+):)?(\d+):([\d.]+)", text)
seconds = 3600 * int(wall.group(1) or 0) + 60 * int(wall.group(2)) + float(wall.group(3))
peak_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", text).group(1))
stages = json.load(open(report_path))["run"]["seconds"]
largest = sorted(stages.items(), key=lambda kv: -kv[1])[:4]
print("| %s | %s | %.1f | %.2f | %s |" % (soup, format(int(faces), ","), seconds, peak_kb / 1e6,
      ", ".join("%s %.1f" % kv for kv in largest)))
EOF
  done
done
