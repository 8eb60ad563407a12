#!/usr/bin/env bash
# Corrects a whole archive on a Slurm cluster: one array task per shard, every
# task writing into one shared output folder. Submit, then merge the shards'
# manifests once all tasks are done:
#
#   sbatch --array=1-16 scripts/slurm_batch.sh /shared/archive /shared/corrected
#   sbatch --dependency=afterany:<JOBID> --wrap 'acmw batch --merge --out /shared/corrected'
#
# Task K corrects the trials of shard K of N (by the SHA-256 of each file name,
# so every task lists the folder and agrees on the split). A task that is
# re-submitted, or the whole array run again, skips what its manifest records
# as done with the same input, settings, table and program version. Shard
# numbers start at 1: keep --array=1-N. Extra arguments after the two folders
# go to `acmw batch` (e.g. --variant drift-heading-centroid --limits FILE).
#SBATCH --job-name=acmw-batch
#SBATCH --cpus-per-task=2
#SBATCH --mem=4G
#SBATCH --time=02:00:00
#SBATCH --output=acmw-batch-%A_%a.log
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: sbatch --array=1-N $0 TRIALS_DIR OUT_DIR [acmw batch options]" >&2
  exit 2
fi
trials=$1
out=$2
shift 2
: "${SLURM_ARRAY_TASK_ID:?submit as a job array: sbatch --array=1-N}"
: "${SLURM_ARRAY_TASK_COUNT:?submit as a job array: sbatch --array=1-N}"
exec acmw batch "$trials" --out "$out" \
  --shard "$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT" \
  --jobs "${SLURM_CPUS_PER_TASK:-1}" --quiet "$@"
