#!/usr/bin/env bash
# Sample a pattern's homogenized energies (thesis App. A.3.1) as a Slurm job array: one shard per
# array task, then merge the shards into one grid, bit-identical to an unsharded run.
#
#   sbatch --array=0-31 tools/slurm-sample.sh PATTERN MODEL OUTDIR
#   # when all tasks are done:
#   yarnhom grid merge OUTDIR/shard-*.grid.yh -o OUTDIR/PATTERN.grid.yh
#
# Each task is resumable: resubmitting a failed or preempted task continues from its checkpoint.
#SBATCH --job-name=yarnhom-sample
#SBATCH --cpus-per-task=8
#SBATCH --time=04:00:00
#SBATCH --requeue
set -euo pipefail
pattern="$1"
model="$2"
out="$3"
count="${SLURM_ARRAY_TASK_COUNT:?run as a job array (sbatch --array=0-N)}"
index="${SLURM_ARRAY_TASK_ID:?run as a job array (sbatch --array=0-N)}"
mkdir -p "$out"
export RAYON_NUM_THREADS="${SLURM_CPUS_PER_TASK:-1}"
exec yarnhom rve sample "$pattern" --model "$model" --shard "$index/$count" \
  -o "$out/shard-$(printf '%04d' "$index").grid.yh"
