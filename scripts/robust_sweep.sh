#!/usr/bin/env bash
# The robust method's sweep (issue 4): 42 synthetic D415 scans (every shape, 640x480 and
# 1280x720, distances 0.30-0.55 m, tilts -20..20 deg), the robust and the paper method on
# each, `groovetrace eval`, trajectory checks (NaN, jumps, tool axis), unorganized and
# robot-base-frame variants, a scan without a groove; writes docs/results-robust.md.
# --set joints: issue 12's shop joints and conditions (about 65 scans in families, the robust
# method, scenes without a joint) into their own section of --results; --set all: both.
#
#   scripts/robust_sweep.sh [--quick] [--only PATTERN] [--set shapes|joints|all]
#       [--bin build/groovetrace] [--out out/robust_sweep]
#       [--results docs/results-robust.md] [--methods robust,paper]
#
# The work is done by scripts/robust_sweep.py (Debian's /usr/bin/python3, standard library).
set -euo pipefail
cd "$(dirname "$0")/.."
exec /usr/bin/python3 scripts/robust_sweep.py --invocation "scripts/robust_sweep.sh${*:+ $*}" "$@"
