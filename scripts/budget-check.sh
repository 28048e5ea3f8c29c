#!/usr/bin/env bash
# Every shared mesh at every budget: `roar reconstruct --faces N` must write exactly N faces,
# closed (watertight, no boundary or non-manifold edge) and free of self-intersections, whatever
# the input's genus (the finish removes handles when N is too small for it). Not part of CI (a
# full run takes hours on 2 cores); prints one line per run and writes DIR/budget-check.tsv.
#
#   scripts/budget-check.sh [--budgets "500 1000 5000"] [--meshes "GLOB ..."] [--out DIR]
#
# Inputs: $ROAR_TEST_DATA/{clean,wild} (default ROAR_TEST_DATA: ../shared/data/meshes beside the
# repo). Uses the release roar under $CARGO_TARGET_DIR (default target/), built first. Exit status 1 when any run breaks a promise.
set -euo pipefail
cd "$(dirname "$0")/.."

budgets="500 1000 5000"
meshes="clean/* wild/*"
out="target/budget-check"
while [ $# -gt 0 ]; do
  case "$1" in
    --budgets) budgets="$2"; shift 2 ;;
    --meshes) meshes="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "budget-check.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
data="${ROAR_TEST_DATA:-../shared/data/meshes}"
[ -d "$data/clean" ] || { echo "budget-check.sh: no $data/clean (set ROAR_TEST_DATA)" >&2; exit 2; }
cargo build --release -p roar-cli --quiet
roar="${CARGO_TARGET_DIR:-target}/release/roar"
mkdir -p "$out"
table="$out/budget-check.tsv"
printf 'mesh\tfaces\tstatus\toutput faces\twatertight\tself-intersecting faces\tinit genus\toutput genus\thandles removed\tseconds\n' > "$table"
failed=0
for pattern in $meshes; do
  for input in "$data"/$pattern; do
    [ -f "$input" ] || continue
    name="$(basename "$(dirname "$input")")-$(basename "$input")"
    for n in $budgets; do
      result="$out/${name%.*}-$n.obj"
      report="$out/${name%.*}-$n.json"
      start=$(date +%s.%N)
      if "$roar" reconstruct "$input" -o "$result" --faces "$n" --report "$report" \
          --quiet 2> "$out/${name%.*}-$n.log"; then
        seconds=$(echo "$(date +%s.%N) - $start" | bc)
        line=$(python3 - "$report" "$n" "$seconds" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); n = int(sys.argv[2])
t = r["output_metrics"]["topology"]
si = r["output_metrics"].get("self_intersections") or {}
bad = si.get("faces")
ok = t["faces"] == n and t["watertight"] and t["boundary_edges"] == 0 \
    and t["nonmanifold_edges"] == 0 and bad == 0
print("\t".join(map(str, ["ok" if ok else "FAIL", t["faces"], t["watertight"], bad,
    r["run"]["init"]["init_genus"], t["genus"], len(r["run"]["finish"]["handles_removed"]),
    "%.1f" % float(sys.argv[3])])))
PY
)
      else
        line="FAIL	error: $(tail -1 "$out/${name%.*}-$n.log")"
      fi
      case "$line" in FAIL*) failed=1 ;; esac
      printf '%s\t%s\t%s\n' "$name" "$n" "$line" | tee -a "$table"
    done
  done
done
exit $failed
