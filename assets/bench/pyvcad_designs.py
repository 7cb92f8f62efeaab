#!/usr/bin/env python3
"""The benchmark designs written for pyvcad 2.3.4, and one timed compile.

Each function below is the pyvcad twin of a volcad design (same geometry,
materials and numbers); `vs_pyvcad.py` names the volcad side. Run under a
Python that has pyvcad 2.3.4 (the `openvcad` wheel; see README.md here):

    pyvcad_designs.py DESIGN png|stl VOXEL_MM

builds DESIGN, prepares it at the voxel size, runs pyvcad's compiler into a
temporary folder and prints one line: `seconds files bytes`, where seconds
is the `compile()` call alone (the design is built and prepared before the
clock starts). `png` is `DirectMaterialCompiler` (one RGBA PNG per layer);
`stl` is `MeshCompiler` (VTK marching cubes, ASCII STL), with the number of
fraction ranges of material id 1 (red) the design lists.
"""
import csv
import os
import shutil
import sys
import tempfile
import time

import pyvcad as pv
import pyvcad_compilers as pc

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.join(HERE, "..", "examples", "data")
M = pv.default_materials


def cube():
    """assets/examples/hello_cube.rhai"""
    return pv.RectPrism(pv.Vec3(0, 0, 0), pv.Vec3(10, 10, 10), M.id("red"))


def graded_bar():
    """assets/examples/graded_bar.rhai (length 15)"""
    bar = pv.RectPrism(pv.Vec3(0, 0, 0), pv.Vec3(15, 10, 5), M.id("gray"))
    exprs = [f"x/{15.0}+0.5", f"-x/{15.0}+0.5"]
    return pv.FGrade(exprs, [M.id("red"), M.id("blue")], True, bar)


def color_sheet():
    """assets/examples/color_sheet.rhai: 12 x 12 swatches of 25 mm, 10 mm thick"""
    s, nx, ny, thickness = 25, 12, 12, 10
    mats = [M.id("cyan"), M.id("magenta"), M.id("white")]
    w, h = s * nx, s * ny
    union = pv.Union()
    for i in range(nx):
        for j in range(ny):
            c = i / (nx - 1)
            m = (1 - c) * j / (ny - 1)
            wf = 1 - (c + m)
            centre = pv.Vec3(-w / 2 + s / 2 + i * s, -h / 2 + s / 2 + j * s, 0)
            base = pv.RectPrism(centre, pv.Vec3(s, s, thickness))
            union.add_child(pv.FGrade([f"{c}", f"{m}", f"{wf}"], mats, True, base))
    return union


def bcc_sphere():
    """assets/examples/bcc_sphere.rhai (strut radius 0.35)"""
    cell = pv.GraphLattice(
        pv.LatticeType.BodyCenteredCubic, pv.Vec3(5, 5, 5), 0.35, M.id("gray")
    )
    sphere = pv.Sphere(pv.Vec3(0, 0, 0), 10)
    return pv.Intersection(False, [pv.Tile(cell), sphere])


def bunny_mesh():
    """assets/bench/bunny_mesh.rhai: the Stanford bunny alone"""
    return pv.Mesh(os.path.join(DATA, "bunny.obj"), M.id("clear"))


def bunny_lattice():
    """assets/examples/bunny_lattice.rhai (strut radius 0.5)"""
    lattice = pv.Union(False)
    with open(os.path.join(DATA, "bunny_struts_3289ish.csv"), newline="") as f:
        for r in csv.DictReader(f):
            a = pv.Vec3(float(r["x1"]), float(r["y1"]), float(r["z1"]))
            b = pv.Vec3(float(r["x2"]), float(r["y2"]), float(r["z2"]))
            frac = float(r["fraction_magenta"])
            strut = pv.Strut(a, b, 0.5, M.id("yellow"))
            grade = pv.FGrade(
                [f"{1.0 - frac}", f"{frac}"], [M.id("yellow"), M.id("magenta")], True, strut
            )
            lattice.add_child(grade)
    lattice.add_child(bunny_mesh())
    return lattice


def pyvcad_sphere():
    """assets/bench/pyvcad_sphere.rhai: pyvcad's own benchmark sphere"""
    return pv.Sphere(pv.Vec3(0, 0, 0), 10, M.id("red"))


def pyvcad_bcc_box():
    """assets/bench/pyvcad_bcc_box.rhai: pyvcad's own benchmark lattice"""
    cell = pv.GraphLattice(
        pv.LatticeType.BodyCenteredCubic, pv.Vec3(2, 2, 2), 0.2, M.id("red")
    )
    box = pv.RectPrism(pv.Vec3(0, 0, 0), pv.Vec3(10, 10, 10), M.id("blue"))
    return pv.Intersection(False, [pv.Tile(cell), box])


# name -> (builder, MeshCompiler's fraction ranges of red)
DESIGNS = {
    "cube": (cube, 1),
    "graded_bar": (graded_bar, 2),
    "color_sheet": (color_sheet, 1),
    "bcc_sphere": (bcc_sphere, 1),
    "bunny_mesh": (bunny_mesh, 1),
    "bunny_lattice": (bunny_lattice, 1),
    "pyvcad_sphere": (pyvcad_sphere, 1),
    "pyvcad_bcc_box": (pyvcad_bcc_box, 1),
}


def main():
    if len(sys.argv) != 4 or sys.argv[1] not in DESIGNS or sys.argv[2] not in ("png", "stl"):
        sys.exit(f"usage: pyvcad_designs.py {'|'.join(DESIGNS)} png|stl VOXEL_MM")
    name, kind, vs = sys.argv[1], sys.argv[2], float(sys.argv[3])
    build, ranges = DESIGNS[name]
    root = build()
    v = pv.Vec3(vs, vs, vs)
    root.prepare(v, 0.1, 0.1)
    out = tempfile.mkdtemp(prefix="pyvcad-bench-")
    try:
        if kind == "png":
            compiler = pc.DirectMaterialCompiler(root, v, M, out, "slice_", False, 0.0)
        else:
            compiler = pc.MeshCompiler(root, v, out, "m", ranges)
        start = time.perf_counter()
        compiler.compile()
        secs = time.perf_counter() - start
        files = os.listdir(out)
        size = sum(os.path.getsize(os.path.join(out, f)) for f in files)
    finally:
        shutil.rmtree(out, ignore_errors=True)
    print(f"{secs:.3f} {len(files)} {size}")


if __name__ == "__main__":
    main()
