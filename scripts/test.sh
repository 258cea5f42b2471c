#!/usr/bin/env bash
# Sets up the dependencies, builds everything and runs the whole test suite (CTest).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/format.sh --check
scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 900
