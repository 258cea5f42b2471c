#!/usr/bin/env bash
# The whole test suite built with AddressSanitizer and UndefinedBehaviorSanitizer in
# ./build-asan (CI runs it after scripts/test.sh). Every finding stops its process
# (-fno-sanitize-recover), so the test that trips one fails. Extra arguments go to ctest.
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
ctest --test-dir build-asan --output-on-failure -j"$(nproc)" --timeout 1800 "$@"
