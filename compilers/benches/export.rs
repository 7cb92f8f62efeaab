//! Export throughput: voxels per second for the PNG slice stack and the
//! segmented mesh export. `cargo bench -p volcad-compilers [-- NAME]`.
//!
//! Plain timers (no criterion), one run each after a small warm-up. For the
//! PNG stack it also times the stages on their own (sampling; sampling and
//! choosing materials) to show what limits the whole: evaluation, PNG
//! encoding or the disk. Output goes to a temporary folder that is removed.
//! `--mesh` or `--png` runs only that export.

// A failed setup step fails the benchmark run.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use glam::DVec3;
use volcad_compilers::dither::Diffuser;
use volcad_compilers::job;
use volcad_compilers::lazy_random::{RunMemo, choose_random_row};
use volcad_compilers::mesh::{MeshFormats, MeshParams, SegmentBy, export_meshes, segment_meshes};
use volcad_compilers::png_stack::{Dither, PngParams, export_png_stack};
use volcad_core::Model;
use volcad_core::sampler::{Consumer, Grid, Sampler, Slab};
use volcad_core::script::{ScriptOptions, model_of, model_of_file};

const BCC_SPHERE: &str = r#"let m = default_materials();
Intersection(false, [Tile(GraphLattice(LatticeType::BodyCenteredCubic, Vec3(5,5,5), 0.175, m.id("red"))), Sphere(Vec3(0,0,0), 10, m.id("blue"))])"#;

struct Case {
    name: &'static str,
    /// Prepared only when the case runs (the bunny takes a while).
    model: fn() -> Arc<Model>,
    /// PNG stack voxel (mm).
    png_voxel: f64,
    /// Mesh voxel (mm) and segmentation.
    mesh_voxel: f64,
    by: SegmentBy,
    segments: usize,
}

fn load(file: &str) -> Arc<Model> {
    load_from("examples", file)
}

/// A design of `assets/<dir>`.
fn load_from(dir: &str, file: &str) -> Arc<Model> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../assets")
        .join(dir)
        .join(file);
    Arc::new(model_of_file(&path).expect("example"))
}

fn inline(src: &str) -> Arc<Model> {
    Arc::new(model_of(src, "bench.rhai", &ScriptOptions::default()).expect("design"))
}

/// Seconds to sample every layer (no fractions / with fractions), and to
/// sample and choose materials, without PNG or disk.
fn stage_times(model: &Model, voxel: f64, dither: Dither) -> (u64, f64, f64) {
    let grid = Grid::covering(&model.bbox(), DVec3::splat(voxel), 1 << 44).expect("grid");
    let [nx, ny, nz] = grid.dims;
    let k = model.materials().len();
    // As the export: random picks leave graded fractions to the chooser.
    let sampler = match dither {
        Dither::Random => Sampler::new(model, grid, Consumer::PngStackRandom),
        Dither::Diffusion => Sampler::new(model, grid, Consumer::PngStackDiffusion),
    };
    let mut slab = Slab::default();
    let t = Instant::now();
    each_slab(&sampler, nz, &mut slab, |_| {});
    let sample = t.elapsed().as_secs_f64();
    let layer = nx * ny;
    let mut codes = vec![0u8; layer];
    let mut diffuser = Diffuser::new(nx, ny, k);
    let t = Instant::now();
    each_slab(&sampler, nz, &mut slab, |slab| {
        let z = slab.z0;
        for l in 0..slab.layers {
            let (d, f) = (
                &slab.dist[l * layer..(l + 1) * layer],
                &slab.fracs[l * layer * k..(l + 1) * layer * k],
            );
            match dither {
                Dither::Random => {
                    use rayon::prelude::*;
                    let lazy = slab.rect_rows(z + l, nx, ny);
                    let shared = RunMemo::applies(model);
                    codes.par_chunks_mut(nx).enumerate().for_each_init(
                        RunMemo::default,
                        |memo, (y, c)| {
                            let v = y * nx;
                            choose_random_row(
                                model,
                                &grid,
                                1,
                                [y, z + l],
                                &d[v..v + nx],
                                &f[v * k..(v + nx) * k],
                                k,
                                lazy.row(y),
                                c,
                                shared.then_some(memo),
                            );
                        },
                    );
                }
                Dither::Diffusion => diffuser.layer(z + l, d, f, &mut codes),
            }
        }
    });
    (grid.count(), sample, t.elapsed().as_secs_f64())
}

/// Samples layers `0..nz` sixteen at a time into `slab`, handing each
/// batch to `per`.
fn each_slab(sampler: &Sampler, nz: usize, slab: &mut Slab, mut per: impl FnMut(&Slab)) {
    let cancel = AtomicBool::new(false);
    let mut z = 0;
    while z < nz {
        let z1 = (z + 16).min(nz);
        sampler.sample_layers(z, z1, slab, &cancel).expect("sample");
        per(slab);
        z = z1;
    }
}

fn run_job<F>(dir: &Path, work: F) -> (f64, volcad_compilers::Summary)
where
    F: FnOnce(&job::JobContext) -> Result<volcad_compilers::Summary, volcad_compilers::ExportError>
        + Send
        + 'static,
{
    let dest = dir.join("out");
    let t = Instant::now();
    let s = job::spawn(dest.clone(), "bench".into(), work)
        .join()
        .expect("export");
    let secs = t.elapsed().as_secs_f64();
    std::fs::remove_dir_all(&dest).expect("clean up");
    (secs, s)
}

fn bytes_of(dir: &Path) -> u64 {
    std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.metadata().map(|m| m.len()).unwrap_or(0))
                .sum()
        })
        .unwrap_or(0)
}

fn main() {
    let filter = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    // `--mesh` / `--png`: only that export.
    let flags: Vec<String> = std::env::args()
        .filter(|a| a == "--mesh" || a == "--png")
        .collect();
    let only = |what: &str| flags.is_empty() || flags.iter().any(|f| f[2..] == *what);
    let tmp = tempfile::tempdir().expect("temp dir");
    println!("threads: {}", rayon::current_num_threads());
    for c in cases() {
        if filter
            .as_ref()
            .is_some_and(|f| !c.name.contains(f.as_str()))
        {
            continue;
        }
        let model = (c.model)();
        if only("png") {
            bench_png(tmp.path(), &c, &model);
        }
        if only("mesh") {
            bench_mesh(tmp.path(), &c, &model);
        }
    }
}

/// The designs and settings measured.
fn cases() -> [Case; 6] {
    [
        Case {
            name: "cube",
            model: || load("hello_cube.rhai"),
            png_voxel: 0.02,
            mesh_voxel: 0.05,
            by: SegmentBy::Dominant,
            segments: 1,
        },
        Case {
            name: "graded_bar",
            model: || load("graded_bar.rhai"),
            png_voxel: 0.02,
            mesh_voxel: 0.05,
            by: SegmentBy::Material(1),
            segments: 4,
        },
        Case {
            name: "bcc_sphere",
            model: || inline(BCC_SPHERE),
            png_voxel: 0.04,
            mesh_voxel: 0.05,
            by: SegmentBy::Dominant,
            segments: 1,
        },
        Case {
            name: "bunny_lattice",
            model: || load("bunny_lattice.rhai"),
            png_voxel: 0.1,
            mesh_voxel: 0.2,
            by: SegmentBy::Dominant,
            segments: 1,
        },
        // pyvcad's own benchmark designs at its 200³ grids (assets/bench);
        // `assets/bench/pyvcad_designs.py pyvcad_sphere png 0.1` (and
        // `pyvcad_bcc_box png 0.05`) times pyvcad 2.3.4 on the same stack.
        Case {
            name: "pyvcad_sphere",
            model: || load_from("bench", "pyvcad_sphere.rhai"),
            png_voxel: 0.1,
            mesh_voxel: 0.1,
            by: SegmentBy::Dominant,
            segments: 1,
        },
        Case {
            name: "pyvcad_bcc_box",
            model: || load_from("bench", "pyvcad_bcc_box.rhai"),
            png_voxel: 0.05,
            mesh_voxel: 0.05,
            by: SegmentBy::Dominant,
            segments: 1,
        },
    ]
}

/// The PNG stack of case `c`, both dithers: the whole export's rate beside
/// its stages' (sampling; sampling and choosing materials).
fn bench_png(tmp: &Path, c: &Case, model: &Arc<Model>) {
    for dither in [Dither::Random, Dither::Diffusion] {
        let (voxels, sample, choose) = stage_times(model, c.png_voxel, dither);
        let p = PngParams {
            voxel: DVec3::splat(c.png_voxel),
            seed: 1,
            dither,
            ..PngParams::default()
        };
        let m = model.clone();
        let probe = tmp.join("size");
        let (secs, s) = run_job(tmp, move |ctx| {
            let s = export_png_stack(&m, &p, ctx)?;
            std::fs::write(&probe, bytes_of(ctx.staging()).to_string()).ok();
            Ok(s)
        });
        let size: u64 = std::fs::read_to_string(tmp.join("size"))
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(0);
        let rate = voxels as f64 / secs / 1e6;
        println!(
            "png  {:<14} {:<9} {:>6} mm {:>12} voxels {:>8.3} s {:>8.1} M voxels/s  (sample {:.0} M/s, sample+choose {:.0} M/s; {} files, {:.1} MB)",
            c.name,
            dither.name(),
            c.png_voxel,
            voxels,
            secs,
            rate,
            voxels as f64 / sample / 1e6,
            voxels as f64 / choose / 1e6,
            s.files.len(),
            size as f64 / 1e6
        );
    }
}

/// The mesh export of case `c`: contouring alone, STL only (pyvcad's
/// output), and all formats.
fn bench_mesh(tmp: &Path, c: &Case, model: &Arc<Model>) {
    let p = MeshParams {
        voxel: DVec3::splat(c.mesh_voxel),
        segments: c.segments,
        by: c.by,
        ..MeshParams::default()
    };
    let t = Instant::now();
    segment_meshes(model, &p, &AtomicBool::new(false), |_, _| {}).expect("meshes");
    let contour = t.elapsed().as_secs_f64();
    // pyvcad's mesh compiler writes STL only: the like-for-like figure.
    let stl_only = MeshParams {
        formats: MeshFormats {
            stl: true,
            obj: false,
            threemf: false,
        },
        ..p.clone()
    };
    let m = model.clone();
    let (stl_secs, _) = run_job(tmp, move |ctx| export_meshes(&m, &stl_only, ctx));
    let m = model.clone();
    let (secs, s) = run_job(tmp, move |ctx| export_meshes(&m, &p, ctx));
    let tris: u64 = s
        .notes
        .iter()
        .filter_map(|n| {
            n.split(" triangles")
                .next()?
                .rsplit(' ')
                .next()?
                .parse::<u64>()
                .ok()
        })
        .sum();
    println!(
        "mesh {:<14} {:<9} {:>6} mm {:>12} voxels {:>8.3} s {:>8.1} M voxels/s  (STL only {:.1} M/s, meshes alone {:.1} M/s; {} segments, {} triangles, STL+OBJ+3MF)",
        c.name,
        "",
        c.mesh_voxel,
        s.units,
        secs,
        s.units as f64 / secs / 1e6,
        s.units as f64 / stl_secs / 1e6,
        s.units as f64 / contour / 1e6,
        s.counts.len(),
        tris
    );
}
