#!/usr/bin/env bash
# Throughput of `roar batch` against plain `roar reconstruct`, side by side in one run, on 2
# cores: the same N items (the example soup, each with its own seed) done
#   (a) by two `roar reconstruct` loops running at once, each over half the items;
#   (b) by one `roar batch --jobs 2`;
#   (c) by two `roar batch --shard I/2` running at once.
# Prints the wall-clock seconds of each and the ratios b/a and c/a.
#
# Usage: scripts/batch-throughput.sh [ROAR] [N]   (default: target/release/roar, 8 items)
set -euo pipefail
roar="$(realpath "${1:-target/release/roar}")"
n="${2:-8}"
work="$(mktemp -d /tmp/roar-throughput.XXXXXX)"
trap 'rm -rf "$work"' EXIT
cd "$work"
"$roar" example-soup chair.obj 2>/dev/null
cat > small.toml <<TOML
[target]
views_per_axis = 3
render_resolution = 128
[init]
init_resolution = 64
[optimize]
iterations = 40
TOML
echo "id,path,seed" > manifest.csv
for i in $(seq 0 $((n - 1))); do echo "item$i,chair.obj,$i" >> manifest.csv; done

now() { date +%s.%N; }
loop() { # reconstruct the items with seeds $1, $1+2, ...
  for i in $(seq "$1" 2 $((n - 1))); do
    "$roar" reconstruct chair.obj -o "plain/$i.obj" --faces 500 --config small.toml --seed "$i" -q
  done
}
mkdir -p plain
t0=$(now); loop 0 & loop 1 & wait; t1=$(now)
"$roar" batch manifest.csv -o jobs2 --faces 500 --config small.toml --jobs 2 -q; t2=$(now)
"$roar" batch manifest.csv -o shards --faces 500 --config small.toml --shard 0/2 -q &
"$roar" batch manifest.csv -o shards --faces 500 --config small.toml --shard 1/2 -q &
wait; t3=$(now)
awk -v t0="$t0" -v t1="$t1" -v t2="$t2" -v t3="$t3" -v n="$n" 'BEGIN {
  a = t1 - t0; b = t2 - t1; c = t3 - t2
  printf "%d items: two reconstruct loops %.1f s, batch --jobs 2 %.1f s (%.3f), two shards %.1f s (%.3f)\n", n, a, b, b / a, c, c / a
}'
