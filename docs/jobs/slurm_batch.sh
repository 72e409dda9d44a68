#!/bin/bash
# Slurm job array running `quadlod batch` over one manifest, one shard per array task
# (docs/batch.md). Submit with:  sbatch --array=0-15 docs/jobs/slurm_batch.sh assets.jsonl
# Every task reads the same manifest and takes the assets i with i mod N == task id; a task
# that is re-run (preempted, failed node) skips the assets whose outputs are already newer than
# their inputs, so resubmitting the whole array after a failure redoes only what is missing.
#SBATCH --job-name=quadlod-batch
#SBATCH --cpus-per-task=2
#SBATCH --mem=4G
#SBATCH --time=02:00:00
#SBATCH --output=logs/quadlod-%A_%a.out
set -euo pipefail
manifest=${1:?usage: sbatch --array=0-N-1 slurm_batch.sh MANIFEST.jsonl}
mkdir -p logs results
# One JSON line per asset on stdout → results/shard-<task>.jsonl; exit code 2 if any failed.
quadlod -q batch "$manifest" --threads "$SLURM_CPUS_PER_TASK" \
  --shard "$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT" \
  > "results/shard-$SLURM_ARRAY_TASK_ID.jsonl"
