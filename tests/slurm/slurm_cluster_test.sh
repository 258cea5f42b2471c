#!/usr/bin/env bash
# Runs a night on a real one-node Slurm cluster started here, on localhost only, and checks it
# against a single-process batch over the same scans:
#   - munged, slurmctld and slurmd (Debian's munge and slurm-wlm) run as this user with their own
#     key, socket, configuration, ports, state and logs in a temporary work dir;
#   - 9 synthetic scans (3 with GT_TEST_SMALL=1), a 3-task array through scripts/slurm/submit.sh
#     and its report job;
#   - every job completes with exit code 0; summary.csv has the same rows as the single
#     batch's (timing columns aside) and every trajectory.csv is byte-identical.
# The daemons are stopped by their PIDs on any exit. GT_KEEP_WORK=1 keeps the work dir.
# Usage: slurm_cluster_test.sh BUILD_DIR SOURCE_DIR [SLOWDOWN]
# SLOWDOWN (default 1) multiplies the wait for the jobs: 5 in a sanitized build. GT_TEST_SMALL=1
# (scripts/test_sanitized.sh) runs one scan per task instead of three.
set -euo pipefail
build=$(cd "$1" && pwd)
src=$(cd "$2" && pwd)
jobs_wait=$((180 * ${3:-1}))
per_task=3
[ "${GT_TEST_SMALL:-0}" = 1 ] && per_task=1
n_scans=$((3 * per_task))
gt=$build/groovetrace
for tool in munged munge slurmctld slurmd sbatch squeue sinfo scontrol scancel; do
  command -v "$tool" >/dev/null || { echo "slurm test: $tool not installed (scripts/setup.sh)" >&2; exit 1; }
done

work=$(mktemp -d /tmp/gt-slurm.XXXXXX)
chmod 0755 "$work"  # munged wants its socket reachable by all users
munged_pid="" ctld_pid="" slurmd_pid=""

stop() {  # stop PID: TERM, wait up to 15 s, then KILL
  local pid=$1
  [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null || return 0
  kill -TERM "$pid" 2>/dev/null || true
  for _ in $(seq 150); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  kill -KILL "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
}
cleanup() {
  set +e
  if [ -n "$ctld_pid" ] && kill -0 "$ctld_pid" 2>/dev/null; then
    scancel --quiet --user="$(id -un)" 2>/dev/null  # this cluster's jobs only (SLURM_CONF)
    for _ in $(seq 50); do [ -z "$(squeue -h -o %i 2>/dev/null)" ] && break; sleep 0.2; done
  fi
  stop "$slurmd_pid"
  stop "$ctld_pid"
  stop "$munged_pid"
  if [ "${GT_KEEP_WORK:-0}" = 1 ]; then echo "slurm test: work dir kept: $work" >&2; else rm -rf "$work"; fi
}
trap cleanup EXIT
trap 'fail "the test to run to its end, saw a signal"' INT TERM HUP

fail() {  # fail MESSAGE: one line, then the tails of the logs
  echo "slurm test FAILED: expected $1 (the logs' tails follow; GT_KEEP_WORK=1 keeps $work)" >&2
  for log in "$work"/munge/munged.out "$work"/munge/munged.log "$work"/slurmctld.out "$work"/slurmctld.log "$work"/slurmd.out "$work"/slurmd.log "$work"/jobs/*.out; do
    [ -f "$log" ] && { echo "--- tail of $log" >&2; tail -n 15 "$log" >&2; }
  done
  exit 1
}

wait_for() {  # wait_for SECONDS COMMAND...: poll every 0.5 s until COMMAND succeeds, else 1
  local secs=$1
  shift
  for _ in $(seq $((secs * 2))); do "$@" && return 0; sleep 0.5; done
  return 1
}

# --- munge: its own key, socket, pid, log and seed files.
mkdir -m 0755 "$work/munge"
dd if=/dev/urandom of="$work/munge/munge.key" bs=1024 count=1 status=none
chown "$(id -u):$(id -g)" "$work/munge/munge.key"
chmod 0400 "$work/munge/munge.key"
socket=$work/munge/munge.socket
munged --foreground --socket="$socket" --key-file="$work/munge/munge.key" \
  --pid-file="$work/munge/munged.pid" --log-file="$work/munge/munged.log" \
  --seed-file="$work/munge/munged.seed" >"$work/munge/munged.out" 2>&1 &
munged_pid=$!
munge_works() { munge -n -S "$socket" 2>/dev/null | unmunge -S "$socket" >/dev/null 2>&1; }
wait_for 20 munge_works || fail "munged answering on $socket within 20 s"

# --- slurm.conf: one node, this host, on 127.0.0.1, two free ports.
port_free() { ! (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
base=$((20000 + ($$ % 4000) * 10))
for _ in $(seq 40); do
  port_free "$base" && port_free $((base + 1)) && break
  base=$((base + 10 < 60000 ? base + 10 : 20000))
done
if ! port_free "$base" || ! port_free $((base + 1)); then fail "two free ports near $base"; fi
host=$(hostname -s)
user=$(id -un)
mkdir -p "$work/state" "$work/spool" "$work/jobs"
conf=$work/slurm.conf
cat >"$conf" <<EOF
ClusterName=gtest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$base
SlurmdPort=$((base + 1))
SlurmUser=$user
SlurmdUser=$user
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
SwitchType=switch/none
ReturnToService=2
SchedulerType=sched/builtin
JobCompType=jobcomp/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=2 RealMemory=500 State=UNKNOWN
PartitionName=gtest Nodes=$host Default=YES MaxTime=60 State=UP
EOF
export SLURM_CONF=$conf
slurmctld -D -c -f "$conf" >"$work/slurmctld.out" 2>&1 &
ctld_pid=$!
slurmd -D -f "$conf" -N "$host" >"$work/slurmd.out" 2>&1 &
slurmd_pid=$!
node_idle() {
  kill -0 "$ctld_pid" 2>/dev/null || fail "slurmctld running, saw it exit"
  kill -0 "$slurmd_pid" 2>/dev/null || fail "slurmd running, saw it exit"
  [ "$(sinfo -h -N -n "$host" -o %t 2>/dev/null)" = idle ]
}
wait_for 60 node_idle || fail "node $host idle within 60 s, sinfo shows '$(sinfo -h -N -o '%N %t %E' 2>&1)'"

# --- the synthetic scans.
mkdir -p "$work/scans"
for k in $(seq "$n_scans"); do
  shape=straight
  [ $((k % 2)) -eq 0 ] && shape=curve
  "$gt" synth --shape "$shape" --seed "$k" --resolution 640x480 -o "$work/scans/scan$k.pcd" >/dev/null ||
    fail "groovetrace synth --shape $shape --seed $k to exit 0"
done

# --- the night on the cluster: a 3-task array and its report job.
export GROOVETRACE=$gt
ids=$(cd "$work/jobs" && "$src/scripts/slurm/submit.sh" "$work/scans" "$work/night" 3 --backend cpu --jobs 1) ||
  fail "scripts/slurm/submit.sh to exit 0"
read -r array report <<<"$ids"
[[ "$array" =~ ^[0-9]+$ && "$report" =~ ^[0-9]+$ ]] || fail "two job ids from submit.sh, saw '$ids'"
queue_empty() { squeue >/dev/null 2>&1 && [ -z "$(squeue -h -o %i)" ]; }
wait_for "$jobs_wait" queue_empty ||
  fail "jobs $array (array) and $report (report) gone within $jobs_wait s, left: $(squeue -h -o '%i %T %r' 2>&1 | paste -sd' ')"

# Every job (3 array tasks and the report) completed with exit code 0.
states=$(for j in "$array" "$report"; do scontrol -o show job "$j"; done 2>&1 |
  grep -oE 'JobId=[0-9]+ (ArrayJobId=[0-9]+ ArrayTaskId=[0-9]+ )?|JobState=[A-Z_]+|\bExitCode=[0-9:]+' | paste -sd' ')
[ "$(grep -o 'JobState=COMPLETED ExitCode=0:0' <<<"$states" | wc -l)" -eq 4 ] ||
  fail "3 array tasks and the report COMPLETED with ExitCode=0:0, saw: $states"

# Each task ran its own third of the scans, its shard taken from the array's environment.
for k in 0 1 2; do
  out="$work/jobs/groovetrace-night-${array}_$k.out"
  line="batch: $per_task scans (shard $k/3): $per_task ok, 0 not ok"
  grep -q "$line" "$out" || fail "task $k logging '$line', saw: $(tail -n 1 "$out" 2>&1)"
done

# --- the same scans in one process.
"$gt" batch "$work/scans" -o "$work/single" --backend cpu --jobs 1 --progress none >/dev/null ||
  fail "the single-process batch to exit 0"

# summary.csv: the same rows, without the timing columns.
rows() {
  python3 - "$1" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1], newline="")))
for r in rows:
    print(repr([(k, v) for k, v in r.items() if k not in ("total_ms", "stages_ms")]))
PY
}
[ -f "$work/night/summary.csv" ] || fail "the report job to write $work/night/summary.csv"
diff <(rows "$work/single/summary.csv") <(rows "$work/night/summary.csv") >"$work/summary.diff" ||
  fail "the same summary.csv rows from the single batch and the array, saw: $(head -c 400 "$work/summary.diff" | tr '\n' ' ')"
n=$(($(wc -l <"$work/night/summary.csv") - 1))
[ "$n" -eq "$n_scans" ] || fail "$n_scans rows in the array's summary.csv, saw $n"

# trajectory.csv: the same files, byte for byte.
trajectories() { (cd "$1" && find . -name trajectory.csv | sort); }
[ "$(trajectories "$work/single")" = "$(trajectories "$work/night")" ] ||
  fail "the same trajectory.csv files, saw single: $(trajectories "$work/single" | paste -sd' ') array: $(trajectories "$work/night" | paste -sd' ')"
t=$(trajectories "$work/night" | wc -l)
[ "$t" -ge "$n_scans" ] || fail "a trajectory.csv per scan ($n_scans), saw $t"
while read -r f; do
  cmp -s "$work/single/$f" "$work/night/$f" || fail "$f byte-identical from the single batch and the array, saw it differ"
done < <(trajectories "$work/night")
echo "slurm test: 3 array tasks and the report completed on $host; $n_scans rows and $t trajectories identical to one process"
