#!/usr/bin/env python3
"""volcad beside pyvcad 2.3.4, alternating, on the same designs and voxels.

    PYVCAD_PYTHON=/tmp/pyvcad/bin/python VOLCAD=target/release/volcad \\
        python3 assets/bench/vs_pyvcad.py [--rounds 3] [--only DESIGN,...] [--kinds png,stl]

For each round, design and compiler it runs pyvcad's compiler (through
`pyvcad_designs.py` under PYVCAD_PYTHON) and then `volcad export` on the
twin design, and prints each pair as it goes; at the end a table of
medians and their ratio. pyvcad's figure is its `compile()` call alone
(design built and prepared before the clock); volcad's is the wall time of
the whole command (process start, script, preparation, export, files),
with its mesh-grid cache in a fresh folder (the first round builds the
grids of imported meshes, later rounds read them, as a second export
would).
Compilers: `png` is the slice stack (pyvcad's DirectMaterialCompiler,
`volcad export png`); `stl` is the mesh export as pyvcad writes it (its
MeshCompiler, `volcad export mesh --formats stl`) with the same fraction
ranges of the same material. Both write into TMPDIR (default /dev/shm, so
a slow disk does not decide). PYVCAD_PRELOAD, if set, is preloaded into
pyvcad (the isoc23 shim on glibc older than 2.38; README.md here).

The voxel sizes are those at which pyvcad's compile takes 5 to 60 s on a
two-core AMD EPYC (x86-64) machine (the bunny lattice's 3,287-child union
costs pyvcad about 1 ms a voxel, hence its coarse voxel); on a faster or
slower machine, `--voxel` overrides them to calibrate. Depends on nothing outside the repository but pyvcad and
the volcad binary.
"""
import argparse
import os
import platform
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
EX = os.path.join("assets", "examples")

# design: (volcad script, {compiler: voxel mm}, volcad's mesh options that
# make pyvcad's fraction ranges of red: one range is the whole part)
CASES = {
    "cube": (f"{EX}/hello_cube.rhai", {"png": 0.028, "stl": 0.022}, ["--segments", "1", "--by", "red"]),
    "graded_bar": (f"{EX}/graded_bar.rhai", {"png": 0.025, "stl": 0.03}, ["--segments", "2", "--by", "red"]),
    "color_sheet": (f"{EX}/color_sheet.rhai", {"png": 0.5, "stl": 0.7}, ["--segments", "1", "--by", "cyan"]),
    "bcc_sphere": (f"{EX}/bcc_sphere.rhai", {"png": 0.045, "stl": 0.055}, ["--segments", "1", "--by", "gray"]),
    "bunny_mesh": ("assets/bench/bunny_mesh.rhai", {"png": 0.12, "stl": 0.13}, ["--segments", "1", "--by", "clear"]),
    "bunny_lattice": (f"{EX}/bunny_lattice.rhai", {"png": 2.0, "stl": 2.5}, ["--segments", "1", "--by", "yellow"]),
}
GRID = re.compile(r"(\d+) [x×] (\d+) [x×] (\d+) voxels")


def run_pyvcad(py, preload, design, kind, voxel, tmp):
    env = dict(os.environ, TMPDIR=tmp)
    if preload:
        env["LD_PRELOAD"] = preload
    cmd = [py, os.path.join(HERE, "pyvcad_designs.py"), design, kind, str(voxel)]
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=ROOT)
    if out.returncode != 0:
        sys.exit(f"pyvcad failed on {design} {kind} {voxel}:\n{out.stderr[-2000:]}")
    return float(out.stdout.split()[0])


def run_volcad(volcad, design, kind, voxel, tmp):
    script, _, mesh_opts = CASES[design]
    dest = os.path.join(tmp, f"volcad-{design}-{kind}")
    shutil.rmtree(dest, ignore_errors=True)
    if kind == "png":
        args = ["png", script]
    else:
        args = ["mesh", script, "--formats", "stl", *mesh_opts]
    cmd = [volcad, "export", *args, "--voxel", str(voxel), "--out", dest]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    env = dict(os.environ, VOLCAD_CACHE_DIR=os.path.join(tmp, "cache"))
    out = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, env=env)
    secs = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    shutil.rmtree(dest, ignore_errors=True)
    if out.returncode != 0:
        sys.exit(f"volcad failed: {' '.join(cmd)}\n{out.stderr[-2000:]}")
    grid = GRID.search(out.stdout + out.stderr)
    return secs, cpu, "x".join(grid.groups()) if grid else "?"


def machine():
    cpu = platform.processor() or "?"
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return f"{os.cpu_count()} logical cores, {cpu}, {platform.system()} {platform.release()}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--only", default=",".join(CASES), help="comma list of designs")
    ap.add_argument("--kinds", default="png,stl", help="comma list of png, stl")
    ap.add_argument("--voxel", type=float, help="override every case's voxel (mm), to calibrate")
    a = ap.parse_args()
    py = os.environ.get("PYVCAD_PYTHON") or sys.exit("set PYVCAD_PYTHON to a python with openvcad 2.3.4")
    volcad = os.path.join(ROOT, os.environ.get("VOLCAD", "target/release/volcad"))
    preload = os.environ.get("PYVCAD_PRELOAD", "")
    designs = [d for d in a.only.split(",") if d]
    kinds = [k for k in a.kinds.split(",") if k]
    for d in designs:
        if d not in CASES:
            sys.exit(f"--only: no design {d!r}; the designs are {', '.join(CASES)}")
    for k in kinds:
        if k not in ("png", "stl"):
            sys.exit(f"--kinds: no compiler {k!r}; write png, stl or png,stl")
    tmp = tempfile.mkdtemp(prefix="vs-pyvcad-", dir=os.environ.get("TMPDIR", "/dev/shm"))
    print(f"# machine: {machine()}; load average {os.getloadavg()[0]:.1f} at the start")
    print("# pyvcad s: its compile() call alone (design built and prepared first)")
    print("# volcad s: wall time of the whole `volcad export` command")
    print("# volcad's mesh-grid cache starts empty (round 1 builds imported meshes' grids, later rounds read them)")
    print(f"# {a.rounds} rounds, pyvcad then volcad per case; ratio = pyvcad median / volcad median")
    times = {}
    try:
        for r in range(1, a.rounds + 1):
            for d in designs:
                for k in kinds:
                    voxel = a.voxel or CASES[d][1][k]
                    p = run_pyvcad(py, preload, d, k, voxel, tmp)
                    v, cpu, grid = run_volcad(volcad, d, k, voxel, tmp)
                    times.setdefault((d, k), (voxel, grid, [], []))
                    times[(d, k)][2].append(p)
                    times[(d, k)][3].append(v)
                    print(f"round {r} {d:<13} {k} {voxel:<5} {grid:>13}  pyvcad {p:8.3f} s  volcad {v:7.3f} s ({cpu:.3f} s CPU)  {p / v:6.1f}x  load {os.getloadavg()[0]:.1f}", flush=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print()
    print(f"{'design':<13} {'compiler':<8} {'voxel mm':>8} {'grid':>13} {'pyvcad s':>9} {'volcad s':>9} {'ratio':>6}  {'volcad min-max s':>16}")
    for (d, k), (voxel, grid, ps, vs) in times.items():
        pm, vm = statistics.median(ps), statistics.median(vs)
        print(f"{d:<13} {k:<8} {voxel:>8} {grid:>13} {pm:>9.2f} {vm:>9.3f} {pm / vm:>5.1f}x  {min(vs):>7.3f}-{max(vs):.3f}")


if __name__ == "__main__":
    main()
