#!/usr/bin/env bash
# Mesh exports of the cube and the graded bar by pyvcad 2.3.4's MeshCompiler
# and by `volcad export mesh`, alternating in the same minutes, on the same
# grids (see pyvcad_mesh.py for the designs and how to install pyvcad).
#
#   PYVCAD_PYTHON=/tmp/pyvcad/bin/python VOLCAD=target/release/volcad \
#     bash assets/bench/mesh_vs_pyvcad.sh [RUNS]
#
# Prints, per run and case, both rates and their ratio (ours the median of
# VOLCAD_RUNS exports, default 5); both write into $TMPDIR (default
# /dev/shm, so the disk does not decide). Set PYVCAD_PRELOAD to the isoc23
# shim on a glibc older than 2.38.
set -euo pipefail
cd "$(dirname "$0")/../.."
runs="${1:-3}"
py="${PYVCAD_PYTHON:?set PYVCAD_PYTHON to a python with openvcad==2.3.4}"
volcad="${VOLCAD:-target/release/volcad}"
export TMPDIR="${TMPDIR:-/dev/shm}"
# design, voxel (mm), pyvcad's segments, the volcad design and its options
# for the same meshes (one for the one-material cube; two ranges of red's
# fraction for the bar). The first two are the voxel sizes `volcad bench`
# uses (10 M voxels).
cases=(
  "cube 0.0464 1 assets/examples/hello_cube.rhai"
  "bar 0.0422 2 assets/examples/graded_bar.rhai --segments 2 --by red"
  "cube 0.02 1 assets/examples/hello_cube.rhai"
  "bar 0.02 2 assets/examples/graded_bar.rhai --segments 2 --by red"
)
printf '%-5s %-7s %-4s %14s %14s %7s\n' design voxel segs pyvcad volcad ratio
for ((r = 1; r <= runs; r++)); do
  for c in "${cases[@]}"; do
    read -r name voxel segs design opts <<<"$c"
    p=$(LD_PRELOAD="${PYVCAD_PRELOAD:-}" "$py" assets/bench/pyvcad_mesh.py "$name" "$voxel" "$segs")
    p_rate=$(awk '{print $6}' <<<"$p")
    # Ours: the median of $VOLCAD_RUNS exports (one lasts a tenth of a
    # second at 10 M voxels, short enough for one hiccup to move it by a
    # third; pyvcad's second-long run is steadier).
    v=$(for ((i = 0; i < ${VOLCAD_RUNS:-5}; i++)); do
      out=$(mktemp -d)
      rm -rf "$out"
      # shellcheck disable=SC2086
      "$volcad" export mesh "$design" --voxel "$voxel" $opts --out "$out" 2>&1 |
        sed -n 's/.*voxels in .* (\(.*\) voxels\/s).*/\1/p'
      rm -rf "$out"
    done | sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}')
    printf '%-5s %-7s %-4s %14.4g %14.4g %7.1f\n' "$name" "$voxel" "$segs" "$p_rate" "$v" \
      "$(awk -v a="$v" -v b="$p_rate" 'BEGIN{print a/b}')"
  done
done
