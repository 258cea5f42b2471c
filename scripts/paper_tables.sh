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
# The work is done by scripts/paper_tables.py (Debian's /usr/bin/python3, standard library).
set -euo pipefail
cd "$(dirname "$0")/.."
exec /usr/bin/python3 scripts/paper_tables.py --invocation "scripts/paper_tables.sh${*:+ $*}" "$@"
