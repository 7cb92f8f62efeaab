//! Points per second near the surface (within 2 mm) for every example, the
//! 3,286-strut bunny lattice and one design per node of issue 34 (Cone,
//! Torus, PolygonRevolve, tapered Strut, Mirror, Identity, Sum, Blend),
//! and the bunny lattice graded as a whole by an FGrade and by a
//! `set_attribute`. A design with attributes gets a second row, `+attrs`:
//! distance, fractions and every attribute in one walk
//! (`Model::eval_with_attributes`, as `volcad sample` asks).
//! `cargo bench -p volcad-core [-- FILTER]`; `VOLCAD_BENCH_POINTS` and
//! `VOLCAD_BENCH_SECONDS` shorten a run (1,000,000 points, 2 s a figure).
//!
//! Plain timers (no criterion): `bench::median_points_per_second`, the
//! median of up to five passes after a warm-up, as `volcad bench` reports.

// A benchmark crate: its helper functions stop on a failed setup as its tests do.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use rayon::prelude::*;
use volcad_core::Model;
use volcad_core::bench::{
    median_of_passes, median_points_per_second, near_surface_points, z_order,
};
use volcad_core::script::{ScriptOptions, run_script};

fn main() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/examples");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "rhai"))
        .collect();
    files.sort();
    let filter = std::env::args().skip(1).find(|a| !a.starts_with('-'));
    println!("threads: {}", rayon::current_num_threads());
    println!(
        "{:<26} {:>7} {:>12} {:>12} {:>16} {:>16}",
        "design", "nodes", "script (s)", "prepare (s)", "random order", "z-order"
    );
    for path in files {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if filter.as_ref().is_some_and(|f| !name.contains(f.as_str())) {
            continue;
        }
        let src = std::fs::read_to_string(&path).unwrap();
        bench(&name, &src, &ScriptOptions::for_file(&path));
    }
    for (name, src) in NODES {
        if filter.as_ref().is_none_or(|f| name.contains(f.as_str())) {
            bench(name, src, &ScriptOptions::default());
        }
    }
    // The lattice's struts are read relative to the examples.
    let lattice = ScriptOptions::for_file(&dir.join("bunny_lattice.rhai"));
    for (name, src) in GRADED_LATTICE {
        if filter.as_ref().is_none_or(|f| name.contains(f.as_str())) {
            bench(name, &format!("{LATTICE} {src}"), &lattice);
        }
    }
}

/// The bunny lattice's 3,286 struts in one union, the bunny after it.
const LATTICE: &str = r#"let m = default_materials();
let lattice = Union();
for r in read_csv("data/bunny_struts_3289ish.csv") {
    lattice.add_child(Strut(Vec3(r.x1, r.y1, r.z1), Vec3(r.x2, r.y2, r.z2), 0.5, m.id("yellow")));
}
let body = Mesh("data/bunny.obj", m.id("clear"));"#;

/// The lattice graded as a whole by one expression: as an FGrade, as a
/// modulus.
const GRADED_LATTICE: [(&str, &str); 2] = [
    (
        "lattice graded: FGrade",
        r#"Union(false, [FGrade(["clamp(0, z/50 + 0.5, 1)", "1 - clamp(0, z/50 + 0.5, 1)"], [m.id("magenta"), m.id("yellow")], true, lattice), body])"#,
    ),
    (
        "lattice graded: modulus",
        r#"lattice.set_attribute("modulus", "500 + 2000*clamp(0, z/50 + 0.5, 1)"); Union(false, [lattice, body])"#,
    ),
];

/// The number in the environment variable `name`, else `default`.
fn setting(name: &str, default: f64) -> f64 {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// One small design per node that pyvcad 3 added (and Sum, Blend).
const NODES: [(&str, &str); 9] = [
    ("node: Cone", "Cone(0.5, 10.0)"),
    ("node: Torus", "Torus(6.0, 1.5)"),
    (
        "node: PolygonRevolve 360",
        "PolygonRevolve([Vec3(0,0,-8), Vec3(7,0,-8), Vec3(10,0,-2), Vec3(6,0,6), Vec3(0,0,6)], Vec3(0,0,-8), Vec3(0,0,6), 360.0)",
    ),
    (
        "node: PolygonRevolve 270",
        "PolygonRevolve([Vec3(0,0,-8), Vec3(7,0,-8), Vec3(10,0,-2), Vec3(6,0,6), Vec3(0,0,6)], Vec3(0,0,-8), Vec3(0,0,6), 270.0)",
    ),
    (
        "node: Strut tapered",
        "Strut(Vec3(0,0,0), Vec3(10,2,1), 1.0, 3.0, CapMode::Sphere, CapMode::HemiSphere)",
    ),
    (
        "node: Mirror",
        "Mirror(Vec3(0,0,0), Vec3(1,-1,0), Sphere(Vec3(8,4,0), 1.5))",
    ),
    ("node: Identity", "Identity(Torus(6.0, 1.5))"),
    (
        "node: Sum",
        "Sum(-1.0, [Sphere(Vec3(-3,0,0), 2.0), Sphere(Vec3(3,0,0), 2.0)])",
    ),
    (
        "node: Blend r5",
        "Blend(5.0, Union(false, [RectPrism(Vec3(-10,0,0), Vec3(20,20,20), 1), RectPrism(Vec3(10,0,0), Vec3(20,20,20), 3)]))",
    ),
];

/// Time one design and print its row.
fn bench(name: &str, src: &str, opts: &ScriptOptions) {
    let t = std::time::Instant::now();
    let d = match run_script(src, name, opts) {
        Ok(d) => d,
        Err(e) => {
            println!("{name:<26} error: {e}");
            return;
        }
    };
    let script = t.elapsed().as_secs_f64();
    let m = Model::prepare(&d.root, d.materials.clone()).unwrap();
    let n = setting("VOLCAD_BENCH_POINTS", 1e6) as usize;
    let budget = std::time::Duration::from_secs_f64(setting("VOLCAD_BENCH_SECONDS", 2.0));
    let pts = near_surface_points(&m, n, 2.0, 7);
    let random = median_points_per_second(&m, &pts, 5, budget);
    let ordered_pts = z_order(&m, &pts);
    let ordered = median_points_per_second(&m, &ordered_pts, 5, budget);
    let row = |name: &str, random: f64, ordered: f64| {
        println!(
            "{name:<26} {:>7} {:>12.3} {:>12.4} {:>16.3e} {:>16.3e}",
            m.node_count(),
            script,
            m.prepare_time().as_secs_f64(),
            random,
            ordered
        );
    };
    row(name, random, ordered);
    if m.attributes().is_empty() {
        return;
    }
    let rate = |pts: &[glam::DVec3]| {
        attribute_points_per_second(&m, &pts[..pts.len().div_ceil(10)]);
        median_of_passes(5, budget, || {
            Ok::<_, ()>(attribute_points_per_second(&m, pts))
        })
        .unwrap_or(f64::NAN)
    };
    row(&format!("{name} +attrs"), rate(&pts), rate(&ordered_pts));
}

/// Points a second of distance, fractions and every attribute in one walk.
fn attribute_points_per_second(m: &Model, pts: &[glam::DVec3]) -> f64 {
    let wanted: Vec<usize> = (0..m.attributes().len()).collect();
    let width: usize = m.attributes().iter().map(|a| a.kind.width()).sum();
    let k = m.materials().len();
    let start = std::time::Instant::now();
    let sum: f64 = pts
        .par_chunks(4096)
        .map(|chunk| {
            let (mut f, mut a) = (vec![0.0; k], vec![0.0; width]);
            let mut acc = 0.0;
            for p in chunk {
                acc += m.eval_with_attributes(*p, &mut f, &wanted, &mut a).unwrap() + a[0];
            }
            acc
        })
        .sum();
    std::hint::black_box(sum);
    pts.len() as f64 / start.elapsed().as_secs_f64()
}
