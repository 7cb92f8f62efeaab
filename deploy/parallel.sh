#!/usr/bin/env bash
# Sharded slice stack with GNU parallel: N `volcad export png --shard K/N`
# tasks, then `volcad merge`; OUT is byte for byte what one
# `volcad export png DESIGN ... --out OUT` writes.
#
# Run:   deploy/parallel.sh N OUT DESIGN [volcad export png options...]
# e.g.:  deploy/parallel.sh 8 seat_png assets/examples/bicycle_seat.rhai --preset j750
#
# Shard K goes to OUT.shards/K (remove OUT.shards once OUT is checked).
# GNU parallel runs one task per core of this machine; extra options come
# from its PARALLEL variable, e.g. across machines that share this folder:
#   PARALLEL="--sshloginfile nodes.txt --workdir $PWD -j1" deploy/parallel.sh 8 ...
# VOLCAD names the volcad binary (default: the one on PATH). A failed
# shard stops the run (--halt) and no merge happens; rerun the script:
# finished shards are exported again (same bytes).
set -euo pipefail
[ $# -ge 3 ] || { sed -n '2,16p' "$0" >&2; exit 2; }
n=$1 out=$2; shift 2
volcad=${VOLCAD:-volcad}

parallel --will-cite --halt now,fail=1 -q "$volcad" export png "$@" --shard "{}/$n" --out "$out.shards/{}" ::: $(seq "$n") && "$volcad" merge "$out" "$out.shards"/*
