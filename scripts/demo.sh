#!/usr/bin/env bash
# Sets up, builds, renders a sample 640x480 D415-like scan of a straight V-groove and runs
# groovetrace on it. Prints where the outputs are.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
mkdir -p out/demo
build/groovetrace synth --shape straight --seed 1 --resolution 640x480 -o out/demo/scan.pcd
build/groovetrace run out/demo/scan.pcd -o out/demo/result
echo "demo: scan in out/demo/scan.pcd, outputs in $(pwd)/out/demo/result"
