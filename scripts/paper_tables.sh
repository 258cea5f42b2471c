#!/usr/bin/env bash
# Reproduces the paper's Tables I and II on synthetic D415 scans: renders five scans per shape
# (straight, curve, box, cylinder) at the paper's point counts, runs every detection method of
# `groovetrace run` on them, scores each with `groovetrace eval`, and writes docs/results.md
# and docs/figures/*.png. Scans and runs go to out/paper_tables/ (git-ignored).
#
#   scripts/paper_tables.sh [--quick] [--bin build/groovetrace] [--out out/paper_tables]
#       [--backend cpu|opencl|auto] [--results FILE.md] [--figures DIR]
#
# --quick: one seed per shape; results and pictures go under --out unless given.
# --sweep: afterwards also the robust method's sweep (issue 4: every shape, 640x480 and
# 1280x720, distances, tilts, unorganized and base-frame clouds; scripts/robust_sweep.sh)
# into docs/results-robust.md, with the same --bin.
# The work is done by scripts/paper_tables.py (Debian's /usr/bin/python3, standard library).
set -euo pipefail
cd "$(dirname "$0")/.."
sweep=0
bin=()
args=()
prev=""
for a in "$@"; do
  if [ "$a" = --sweep ]; then sweep=1; else args+=("$a"); fi
  if [ "$prev" = --bin ]; then bin=(--bin "$a"); fi
  prev="$a"
done
/usr/bin/python3 scripts/paper_tables.py --invocation "scripts/paper_tables.sh${*:+ $*}" \
  ${args[@]+"${args[@]}"}
if [ "$sweep" = 1 ]; then exec scripts/robust_sweep.sh ${bin[@]+"${bin[@]}"}; fi
