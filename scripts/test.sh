#!/usr/bin/env bash
# Sets up the dependencies, builds everything and runs the whole test suite (CTest), then the
# same suite built with AddressSanitizer and UndefinedBehaviorSanitizer (scripts/test_sanitized.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/format.sh --check
scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 900
scripts/test_sanitized.sh
