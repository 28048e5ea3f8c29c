#!/usr/bin/env bash
# A real one-node SLURM cluster on this machine, running `roar batch` as a job array through
# scripts/roar-batch.sbatch: it checks every output and the batch report, then cancels one task
# in the middle of an item, resubmits the array and checks that finished items were not redone
# and the interrupted one was completed. Every daemon it starts is stopped by its pid on exit.
#
# Usage: scripts/ci-slurm.sh [ROAR]   (default: target/release/roar, built first)
# Needs root (it installs Debian's slurmctld, slurmd, slurm-client and munge when absent).
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$(pwd)"

if [ "$(id -u)" != 0 ]; then
  echo "ci-slurm: needs root (it runs the SLURM daemons)" >&2
  exit 1
fi
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null \
  || ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
  echo "== installing slurmctld slurmd slurm-client munge"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurmctld slurmd slurm-client munge >/dev/null
fi

if [ -n "${1:-}" ]; then
  roar="$1"
else
  # A no-op after `cargo test --release`, which builds the binary too.
  cargo build --release -p roar-cli
  roar="$repo/target/release/roar"
fi
roar="$(cd "$(dirname "$roar")" && pwd)/$(basename "$roar")"

work="$(mktemp -d /tmp/roar-slurm.XXXXXX)"
host="$(hostname -s)"
export SLURM_CONF="$work/slurm.conf"

stop_daemons() {
  status=$?
  if command -v scancel >/dev/null && [ -f "$work/slurmctld.pid" ]; then
    scancel --full --quiet --partition=ci 2>/dev/null || true
  fi
  for daemon in slurmd slurmctld munged; do
    pidfile="$work/$daemon.pid"
    if [ -s "$pidfile" ]; then
      pid="$(cat "$pidfile")"
      kill "$pid" 2>/dev/null || true
      for _ in $(seq 100); do
        kill -0 "$pid" 2>/dev/null || break
        sleep 0.1
      done
      if kill -0 "$pid" 2>/dev/null; then
        echo "ci-slurm: $daemon (pid $pid) did not stop on SIGTERM; killing it" >&2
        kill -9 "$pid" 2>/dev/null || true
      fi
    fi
  done
  if [ "$status" != 0 ]; then
    echo "ci-slurm: FAILED; daemon logs:" >&2
    tail -n 20 "$work"/*.log >&2 2>/dev/null || true
  fi
  rm -rf "$work"
  exit "$status"
}
trap stop_daemons EXIT

fail() {
  echo "ci-slurm: FAILED: $*" >&2
  exit 1
}

echo "== munge and a one-node slurm.conf for $host"
mkdir -p "$work/state" "$work/spool" "$work/munge" "$work/logs"
chmod 700 "$work/munge"
mungekey --create --keyfile="$work/munge/munge.key" --force
munged --force --key-file="$work/munge/munge.key" --socket="$work/munge/munge.socket" \
  --pid-file="$work/munged.pid" --log-file="$work/munged.log" --seed-file="$work/munge/seed"
cat > "$SLURM_CONF" <<CONF
ClusterName=roarci
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$work/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
JobCompType=jobcomp/filetxt
JobCompLoc=$work/jobcomp.txt
ReturnToService=2
MpiDefault=none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=2000 State=UNKNOWN
PartitionName=ci Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"

echo "== waiting for the node to be idle"
started=$(date +%s.%N)
for _ in $(seq 300); do
  state="$(sinfo --noheader --nodes="$host" --format=%T 2>/dev/null || true)"
  [ "$state" = idle ] && break
  sleep 0.1
done
[ "$state" = idle ] || fail "node state is '$state' after 30 s"
awk -v a="$started" -v b="$(date +%s.%N)" 'BEGIN { printf "cluster ready in %.1f s\n", b - a }'

echo "== a small dataset: generated soups, two budgets"
data="$work/data"
mkdir -p "$data"
for ext in obj ply off stl; do
  "$roar" example-soup "$data/chair.$ext" 2>/dev/null
done
cat > "$data/tiny.toml" <<TOML
[target]
views_per_axis = 2
render_resolution = 64
point_cloud_samples = 5000
sharp_edge_samples = 1000
[init]
init_resolution = 32
init_max_faces = 4000
[loss]
planar_max_samples = 5000
[optimize]
working_budget_min = 600
split_interval = 3
smoothing_interval = 2
level_window = 0
TOML
# Shard 1 of 2 runs `b` then `slow`: `slow` has enough iterations to be cancelled mid-item (all
# of them run: `level_window = 0`).
cat > "$data/manifest.csv" <<CSV
id,path,iterations
a,chair.obj,
b,chair.ply,
c,chair.off,
slow,chair.stl,400
CSV
out="$work/out"
submit() {
  MANIFEST="$data/manifest.csv" OUTDIR="$out" FACES=200,400 ROAR="$roar" \
    CONFIG="$data/tiny.toml" ROAR_BATCH_ARGS="--iterations 4" \
    sbatch --parsable --array=0-1 --cpus-per-task=1 --time=5 --chdir="$work" \
    --output="$work/logs/%A_%a.out" "$@" scripts/roar-batch.sbatch
}
records() {
  # Every finished record with its modification time, to tell a rewrite from a skip.
  find "$out" -name '[0-9]*.json' ! -name '*.failure.json' ! -name '*.partial.json' \
    -printf '%P %T@\n' | sort
}

echo "== array job, then cancel task 1 in the middle of 'slow'"
job="$(submit)"
echo "submitted array job $job"
for _ in $(seq 600); do
  [ -f "$out/slow/200.log" ] && break
  sleep 0.1
done
[ -f "$out/slow/200.log" ] || fail "the slow item never started"
sleep 1
[ -f "$out/slow/200.json" ] && fail "the slow item finished before it could be cancelled"
scancel "${job}_1"
for _ in $(seq 600); do
  [ -z "$(squeue --noheader --jobs="$job" 2>/dev/null)" ] && break
  sleep 0.2
done
[ -z "$(squeue --noheader --jobs="$job")" ] || fail "job $job still queued after 2 minutes"
scontrol show job "$job" | grep -E "JobId=|JobState=" || true
cat "$work/logs/${job}_0.out"
for id in a c; do
  for budget in 200 400; do
    [ -f "$out/$id/$budget.json" ] && [ -f "$out/$id/$budget.obj" ] || fail "$id/$budget missing after shard 0"
  done
done
[ -f "$out/slow/200.json" ] && fail "the cancelled item has a record"
"$roar" batch-report "$out" > "$work/report-1.md"
grep -q "\*\*0 failed\*\*" "$work/report-1.md" || fail "the first report has failures: $(cat "$work/report-1.md")"
grep -q "slow/200" "$work/report-1.md" || fail "the first report does not list slow/200 as missing"
before="$(records)"
echo "finished before the resubmission: $(echo "$before" | wc -l) item budgets"

echo "== resubmitted array (resume)"
job2="$(submit --wait)" || fail "the resubmitted array failed: $(cat "$work"/logs/*.out)"
cat "$work/logs/${job2}_0.out" "$work/logs/${job2}_1.out"
after="$(records)"
# Every record that existed before is unchanged (same mtime): nothing finished was redone.
while read -r line; do
  grep -qxF "$line" <<< "$after" || fail "finished item rewritten on resume: $line"
done <<< "$before"
grep -q "already done" "$work/logs/${job2}_0.out" || fail "shard 0 did not skip its finished items"
grep -q "already done" "$work/logs/${job2}_1.out" || fail "shard 1 did not skip its finished item"
"$roar" batch-report "$out" > "$work/report-2.md"
cat "$work/report-2.md"
grep -q "8 item budgets: \*\*8 done\*\*, \*\*0 failed\*\*, \*\*0 missing\*\*" "$work/report-2.md" \
  || fail "the final report is not 8 of 8 done"
for id in a b c slow; do
  for budget in 200 400; do
    info="$("$roar" info --json "$out/$id/$budget.obj")" || fail "roar info $id/$budget.obj failed"
    grep -q "\"faces\": $budget," <<< "$info" || fail "$id/$budget.obj does not have $budget faces: $info"
    grep -q '"closed_manifold": true' <<< "$info" || fail "$id/$budget.obj is not a closed manifold"
  done
done
[ -z "$(find "$out" -name '*.partial.*' -o -name '*.tmp')" ] || fail "leftover partial files"
echo "ci-slurm: ok (array, cancel, resume: 8 of 8 item budgets, none redone)"
