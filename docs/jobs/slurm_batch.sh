#!/bin/bash
# Slurm job array running `quadlod batch` over one manifest, one shard per array task
# (docs/batch.md). Submit from the folder that holds the manifest: the tasks run there, and
# results/ and the logs land there.
#   sbatch --array=0-15 slurm_batch.sh assets.jsonl        # 16 shards
#   sbatch --array=3,11 slurm_batch.sh assets.jsonl 16     # shards 3 and 11 of those 16 again
# The shard count is the second argument, else the array's task count: give it when submitting
# only some indices (with --array=3,11 alone the task count is 2). Array indices are shard
# numbers, 0 <= index < count.
# Every task reads the same manifest and takes the assets i with i mod N == its index. A task run
# again (requeued, resubmitted) skips the assets whose outputs its earlier run recorded as done
# and still current, repeating their recorded metrics, so its results/shard-<index>.jsonl is
# complete again; it redoes the others and removes the temp files a SIGKILL left.
#
# One core per task: many small assets run as many tasks as there are cores. For large meshes
# give more (sbatch --cpus-per-task=8 …); --threads follows. Measured on a 2-core node (docs/batch.md).
#SBATCH --job-name=quadlod-batch
#SBATCH --cpus-per-task=1
#SBATCH --mem=4G
#SBATCH --time=02:00:00
# Slurm opens the log before the script runs, so it goes to the submit folder itself: a
# logs/ folder would have to exist before sbatch.
#SBATCH --output=%x-%A_%a.out
set -euo pipefail
manifest=${1:?usage: sbatch --array=0-N-1 slurm_batch.sh MANIFEST.jsonl [N]}
shards=${2:-$SLURM_ARRAY_TASK_COUNT}
mkdir -p results
# One JSON line per asset on stdout → results/shard-<index>.jsonl; exit code 2 if any failed.
quadlod -q batch "$manifest" --threads "${SLURM_CPUS_PER_TASK:-1}" \
  --shard "$SLURM_ARRAY_TASK_ID/$shards" \
  > "results/shard-$SLURM_ARRAY_TASK_ID.jsonl"
