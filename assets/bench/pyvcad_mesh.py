#!/usr/bin/env python3
"""pyvcad 2.3.4's MeshCompiler on the studio's cube and graded bar, timed.

The export issue's mesh target is "at least 20 times pyvcad's throughput on
the same design and voxel size". This script builds in pyvcad the designs of
`assets/examples/hello_cube.rhai` (a 10 mm cube) and `graded_bar.rhai` (a
15 x 10 x 5 mm bar graded red to blue along x, string expressions), runs
`MeshCompiler` into a temporary folder and prints one line per run:

    design voxel_mm segments seconds voxels voxels_per_s stl_bytes

`voxels` is the grid we export at that voxel size (the design's box padded
by one voxel, as `volcad export mesh` reports it), so the rates compare the
same grids. pyvcad's segments are ranges of material id 1's fraction (red
for the bar); `volcad export mesh ... --segments N --by red` makes the same
ranges. Its output is one ASCII STL per range (VTK marching cubes).

Usage (pyvcad 2.3.4 is the `openvcad` wheel on PyPI):

    python3 -m venv /tmp/pyvcad && /tmp/pyvcad/bin/pip install --no-deps openvcad==2.3.4
    /tmp/pyvcad/bin/python assets/bench/pyvcad_mesh.py cube 0.0464 1
    /tmp/pyvcad/bin/python assets/bench/pyvcad_mesh.py bar 0.0422 2

The 2.3.4 wheel is tagged manylinux_2_28 but calls glibc 2.38's
`__isoc23_strtol` family; on Debian 12 (glibc 2.36) preload a shim that
forwards them to `strtol` and friends (`assets/bench/isoc23_shim.c`, see its
header), which changes nothing for these designs.
"""
import math
import os
import shutil
import sys
import tempfile
import time

import pyvcad as pv
import pyvcad_compilers as pc


def cube():
    return pv.RectPrism(pv.Vec3(0, 0, 0), pv.Vec3(10, 10, 10), 1)


def bar():
    body = pv.RectPrism(pv.Vec3(0, 0, 0), pv.Vec3(15, 10, 5), 1)
    return pv.FGrade(["x/15+0.5", "-x/15+0.5"], [1, 2], True, body)


DESIGNS = {"cube": (cube, (10.0, 10.0, 10.0)), "bar": (bar, (15.0, 10.0, 5.0))}


def main():
    if len(sys.argv) != 4 or sys.argv[1] not in DESIGNS:
        sys.exit("usage: pyvcad_mesh.py cube|bar VOXEL_MM SEGMENTS")
    name, vs, segments = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
    make, size = DESIGNS[name]
    root = make()
    v = pv.Vec3(vs, vs, vs)
    root.prepare(v, 0.1, 0.1)
    # Our grid at this voxel size: ceil(extent / voxel) + 2 per axis.
    voxels = math.prod(math.ceil(s / vs - 1e-9) + 2 for s in size)
    out = tempfile.mkdtemp(prefix="pyvcad-mesh-")
    try:
        start = time.perf_counter()
        pc.MeshCompiler(root, v, out, "m", segments).compile()
        secs = time.perf_counter() - start
        stl = sum(os.path.getsize(os.path.join(out, f)) for f in os.listdir(out))
    finally:
        shutil.rmtree(out, ignore_errors=True)
    print(f"{name} {vs} {segments} {secs:.3f} {voxels} {voxels / secs:.4g} {stl}")


if __name__ == "__main__":
    main()
