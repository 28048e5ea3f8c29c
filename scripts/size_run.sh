#!/usr/bin/env bash
# The size run: generates a 5 M-face soup (scripts/size_run.py) in a temporary folder and runs
# `roar info`, `roar eval` and `roar reconstruct --faces 5000` on it with the release binary,
# printing each command's wall time and peak memory (/usr/bin/time -v). Not part of CI.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p roar-cli
roar="$PWD/target/release/roar"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
python3 scripts/size_run.py "$work/soup.stl" "${FACES:-5000000}"
measure() {
  echo "== $*"
  /usr/bin/time -v "$@" > "$work/stdout" 2> "$work/stderr" || { tail -3 "$work/stderr"; return 1; }
  grep -E "Elapsed|Maximum resident" "$work/stderr"
}
measure "$roar" info "$work/soup.stl"
measure "$roar" eval "$work/soup.stl"
measure "$roar" reconstruct "$work/soup.stl" -o "$work/out.obj" --faces 5000 -q
measure "$roar" info "$work/out.obj"
cat "$work/stdout"
