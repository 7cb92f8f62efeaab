#!/usr/bin/env bash
#SBATCH --job-name=volcad-shard
#SBATCH --cpus-per-task=8
#SBATCH --mem=16G
#SBATCH --time=04:00:00
# Sharded slice stack on Slurm: a job array of N `volcad export png
# --shard K/N` tasks, then a `volcad merge` job that starts when every
# task has succeeded (--dependency=afterok). OUT is byte for byte what one
# `volcad export png DESIGN ... --out OUT` writes.
#
# Run on the login node, in a folder every node sees (shared file system):
#   deploy/slurm.sh N OUT DESIGN [volcad export png options...]
#   e.g. deploy/slurm.sh 16 seat_png bicycle_seat.rhai --preset j750
# Shard K goes to OUT.shards/K (remove OUT.shards once OUT is checked).
# Resources: edit the #SBATCH lines above, or pass sbatch options in
# SBATCH_ARGS (e.g. SBATCH_ARGS="--partition=cpu --account=lab"). VOLCAD
# names the volcad binary (default: the one on PATH). A failed task can be
# rerun alone: sbatch --array=K deploy/slurm.sh N OUT DESIGN ...; then run
# the merge by hand: volcad merge OUT OUT.shards/*
set -euo pipefail
[ $# -ge 2 ] || { sed -n '7,20p' "$0" >&2; exit 2; }
n=$1 out=$2; shift 2
volcad=${VOLCAD:-volcad}

if [ -n "${VOLCAD_MERGE:-}" ]; then
  # The merge job.
  exec "$volcad" merge "$out" "$out.shards"/*
elif [ -n "${SLURM_ARRAY_TASK_ID:-}" ]; then
  # One array task: shard K = SLURM_ARRAY_TASK_ID (1..N) on its allocated cores.
  # shellcheck disable=SC2086
  exec "$volcad" export png "$@" ${SLURM_CPUS_PER_TASK:+--threads=$SLURM_CPUS_PER_TASK} \
    --shard "$SLURM_ARRAY_TASK_ID/$n" --out "$out.shards/$SLURM_ARRAY_TASK_ID"
else
  # On the login node: submit the array, then the merge after it.
  # shellcheck disable=SC2086
  array=$(sbatch --parsable ${SBATCH_ARGS:-} --array="1-$n" "$0" "$n" "$out" "$@")
  # shellcheck disable=SC2086
  sbatch --parsable ${SBATCH_ARGS:-} --job-name=volcad-merge --cpus-per-task=2 \
    --dependency="afterok:${array%%;*}" --export=ALL,VOLCAD_MERGE=1 "$0" "$n" "$out"
fi
