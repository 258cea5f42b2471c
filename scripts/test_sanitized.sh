#!/usr/bin/env bash
# The test suite built with AddressSanitizer and UndefinedBehaviorSanitizer in ./build-asan,
# less the tests named below; scripts/test.sh runs it after the Release suite. Every finding
# stops its process (-fno-sanitize-recover), so the test that trips one fails. Extra arguments
# go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Release -DGT_SANITIZE=address,undefined >/dev/null
cmake --build build-asan -j"$(nproc)"
# Leaks inside the OpenCL ICD loader, PoCL and VTK (libraries we do not build) are theirs:
# scripts/lsan.supp names them; a leak in groovetrace's own code still fails.
# use_sigaltstack=0: with ASan's alternate signal stacks, a thread ending while the process
# exits made ASan fail its own unmapping of that stack (CHECK "unable to unmap", exit 1) in
# most CLI tests; our code sets no signal stack of its own.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:strict_string_checks=1:use_sigaltstack=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0"
# A sanitized scan runs about ten times slower: the tests that run whole scans again and again
# run fewer or smaller ones (tests/support/scenes.hpp, small_runs), with the same assertions.
export GT_TEST_SMALL=1
# Left to the Release suite: a third of this suite's time instrumented, for little that the
# tests kept here do not run. Tests whose subject is the process rather than its memory - a
# real Slurm cluster and the installed package; kills at random moments, a hang past its time
# limit, concurrent runs and thread counts (races are ThreadSanitizer's field); the peak memory
# of runs (ASan's shadow and quarantine would be what they measure); a batch of depth PNGs (the
# PNG reader and the batch run here in their own tests) - and full-frame (1280x720) accuracy
# scenes whose stages 640x480 scenes and section tests run here (a bevel at the coarser scale,
# tacks, high-low, a channel beside a loose bar).
release_only=(
  slurm_cluster install_consumer 'Resources\.PeakMemoryOfARunIsBoundedByItsPoints'
  'OutputSet\.KillsAtRandomMomentsLeaveOneWholeSet' 'OutputSet\.ConcurrentRunsNeverMix'
  'CliBatch\.KilledBatchResumes' 'CliBatch\.HangingScanTimesOut'
  'CliRun\.OutputsAreTheSameForEveryThreadCount'
  'CliDepthPng\.BatchTakesDepthPngsWithIntrinsicsAndNotItsOwnPictures'
  'RobustDetect\.SingleBevelIsReadAtACoarserScaleWhenTheBaseFails'
  'RobustDetect\.TacksAreReportedAndThePathStaysOnTheRoot'
  'RobustDetect\.HighLowIsReportedAndALevelJointIsNot'
  'RobustDetect\.ChannelBesideALooseBarIsNoJoint'
)
exclude="^($(IFS='|'; echo "${release_only[*]}"))\$"
log=build-asan/sanitized-ctest.log
set +e
ctest --test-dir build-asan --output-on-failure -j"$(nproc)" --timeout 1800 -E "$exclude" "$@" \
  2>&1 | tee "$log"
rc=${PIPESTATUS[0]}
set -e
[ "$rc" -eq 0 ] && exit 0
# LeakSanitizer's own stop-the-world tracer now and then crashes as a process exits, after
# the test passed ("Tracer caught signal 11 ... LeakSanitizer has encountered a fatal error",
# google/sanitizers#1353; seen once in 400 tests on a loaded machine). That is not a finding:
# only when every failure is one of those are the failed tests run once more.
failed=$(grep -c ' Test  *#[0-9]*: .*\*\*\*' "$log" || true)  # Failed, Timeout, Exception
tracer=$(grep -c '^Tracer caught signal' "$log" || true)
if [ "$failed" -gt 0 ] && [ "$tracer" -ge "$failed" ]; then
  echo "test_sanitized: $failed failure(s), all LeakSanitizer tracer crashes: running them again"
  ctest --test-dir build-asan --output-on-failure --timeout 1800 --rerun-failed
else
  exit 1
fi
