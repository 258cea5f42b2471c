#!/usr/bin/env bash
# Fuzzes every reader with libFuzzer (docs/fuzzing.md).
#   scripts/fuzz.sh [SECONDS] [HARNESS...]
# Builds the harnesses with clang into build-fuzz/ (ASan + UBSan, CPU backend), writes the seed
# corpus (build-fuzz/seeds), then runs each harness for SECONDS (default 60), FUZZ_PARALLEL at
# a time.
# Each keeps its growing corpus in build-fuzz/corpus/NAME and its crashes, timeouts and
# out-of-memory inputs in build-fuzz/crashes/NAME; its log is build-fuzz/logs/NAME.log. Prints
# per harness the executions, their rate, the coverage (cov: edges, ft: features) and whether
# it found anything. Exits 1 if any harness did.
# Environment: FUZZ_JOBS (make's -j for the build, default 1), FUZZ_PARALLEL (harnesses run at
# once, default 1), FUZZ_TIMEOUT (seconds an input
# may take before it is a finding, default 10), FUZZ_RSS_MB (memory limit, default 2048).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
all=(fuzz_pcd fuzz_ply fuzz_config_yaml fuzz_config_json fuzz_calibration_yaml
     fuzz_calibration_json fuzz_manifest fuzz_depth_png fuzz_depth_intrinsics)
harnesses=("${all[@]}")
[ $# -eq 0 ] || harnesses=("$@")
[[ "$seconds" =~ ^[0-9]+$ ]] || { echo "usage: scripts/fuzz.sh [SECONDS] [HARNESS...]" >&2; exit 2; }

command -v clang++ >/dev/null || { echo "fuzz: clang is missing (scripts/setup.sh)" >&2; exit 1; }
B=build-fuzz
# OpenCL is left out: no reader uses it. Release with assertions and debug info for the reports.
CC=clang CXX=clang++ cmake -S . -B "$B" -DGT_FUZZ=ON -DWITH_OPENCL=OFF -DBUILD_TESTS=OFF \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$B" --target fuzzers -j "${FUZZ_JOBS:-1}"

rm -rf "$B/seeds" "$B/dicts"
"$B/fuzz/fuzz_seeds" "$B"
# The harnesses write each input to a file in a directory of their own under here: in memory
# (/dev/shm) where there is one, so that no input waits for a disk.
mkdir -p "$B/logs"
if GT_FUZZ_TMPDIR=$(mktemp -d /dev/shm/groovetrace-fuzz.XXXXXX 2>/dev/null); then :; else
  GT_FUZZ_TMPDIR="$PWD/$B/tmp"
  rm -rf "$GT_FUZZ_TMPDIR" && mkdir -p "$GT_FUZZ_TMPDIR"
fi
export GT_FUZZ_TMPDIR
trap 'rm -rf "$GT_FUZZ_TMPDIR"' EXIT

seeds_of() {  # harness name -> its seed folder and dictionary
  local n=${1#fuzz_}
  echo "$B/seeds/$n" "$B/dicts/${n%_*}.dict"
}
# One harness: its process's exit status is the finding, its log holds the numbers; the result
# line goes to $B/logs/NAME.result.
fuzz_one() {
  local h=$1 seed_dir dict corpus crashes log status=0 runs rate last cov ft result
  read -r seed_dir dict < <(seeds_of "$h")
  corpus="$B/corpus/$h" crashes="$B/crashes/$h" log="$B/logs/$h.log"
  mkdir -p "$corpus" "$crashes"
  "$B/fuzz/$h" "$corpus" "$seed_dir" -dict="$dict" -max_total_time="$seconds" \
    -timeout="${FUZZ_TIMEOUT:-10}" -rss_limit_mb="${FUZZ_RSS_MB:-2048}" -print_final_stats=1 \
    -artifact_prefix="$crashes/" >"$log" 2>&1 || status=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  last=$(grep -E '^#[0-9]+' "$log" | tail -1 || true)
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")
  result=ok
  [ "$status" -eq 0 ] || result="FOUND (exit $status): $(ls -t "$crashes" | head -1) - see $log"
  printf '%-22s %12s %8s %8s %8s  %s\n' "$h" "${runs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" \
    "$result" >"$B/logs/$h.result"
}

for h in "${harnesses[@]}"; do
  [ -x "$B/fuzz/$h" ] || { echo "fuzz: no harness $h (one of: ${all[*]})" >&2; exit 2; }
  rm -f "$B/logs/$h.result"
done
# FUZZ_PARALLEL harnesses at a time (default 1): each is one process on one core.
parallel=${FUZZ_PARALLEL:-1}
[[ "$parallel" =~ ^[1-9][0-9]*$ ]] || { echo "fuzz: FUZZ_PARALLEL must be a positive integer" >&2; exit 2; }
for h in "${harnesses[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$parallel" ]; do wait -n || true; done
  fuzz_one "$h" &
done
wait || true
found=0
printf '%-22s %12s %8s %8s %8s  %s\n' harness executions exec/s cov ft result
for h in "${harnesses[@]}"; do
  cat "$B/logs/$h.result" 2>/dev/null || { echo "$h: no result (see $B/logs/$h.log)"; found=1; }
  grep -q FOUND "$B/logs/$h.result" 2>/dev/null && found=1
done
exit "$found"
