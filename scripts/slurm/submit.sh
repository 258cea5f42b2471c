#!/usr/bin/env bash
# Submits a night: an array of TASKS batch shards over INPUT into OUTDIR, then a report job that
# runs `groovetrace report OUTDIR` once the whole array has ended (afterany: also when a shard
# exits 6 because a scan failed). Further arguments go to every shard's `groovetrace batch`.
# Prints the two job ids: ARRAY_ID REPORT_ID. sbatch options can be set through SBATCH_*
# variables (SBATCH_PARTITION, SBATCH_TIMELIMIT, ...); GROOVETRACE names the binary.
#   submit.sh INPUT OUTDIR [TASKS [BATCH FLAGS...]]
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: submit.sh INPUT OUTDIR [TASKS [BATCH FLAGS...]]" >&2; exit 2; }
input=$1 outdir=$2 tasks=${3:-4}
shift $(($# < 3 ? $# : 3))
here=$(cd "$(dirname "$0")" && pwd)
gt=${GROOVETRACE:-groovetrace}
mkdir -p "$outdir"
array=$(sbatch --parsable --array=0-$((tasks - 1)) "$here/night.sbatch" "$input" -o "$outdir" "$@")
array=${array%%;*}  # --parsable prints JOBID[;CLUSTER]
report=$(sbatch --parsable --dependency=afterany:"$array" --job-name=groovetrace-report \
  --output=groovetrace-report-%j.out --wrap "$(printf '%q ' "$gt" report "$outdir")")
echo "$array ${report%%;*}"
