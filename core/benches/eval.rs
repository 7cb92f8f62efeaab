//! Points per second near the surface (within 2 mm) for every example, the
//! 3,286-strut bunny lattice and one design per node of issue 34 (Cone,
//! Torus, PolygonRevolve, tapered Strut, Mirror, Identity, Sum, Blend).
//! `cargo bench -p volcad-core`.
//!
//! Plain timers (no criterion): `bench::median_points_per_second`, the
//! median of up to five passes after a warm-up, as `volcad bench` reports.

// A benchmark crate: its helper functions stop on a failed setup as its tests do.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use volcad_core::Model;
use volcad_core::bench::{median_points_per_second, near_surface_points, z_order};
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
    let pts = near_surface_points(&m, 1_000_000, 2.0, 7);
    let budget = std::time::Duration::from_secs(2);
    let random = median_points_per_second(&m, &pts, 5, budget);
    let pts = z_order(&m, &pts);
    let ordered = median_points_per_second(&m, &pts, 5, budget);
    println!(
        "{name:<26} {:>7} {:>12.3} {:>12.4} {:>16.3e} {:>16.3e}",
        m.node_count(),
        script,
        m.prepare_time().as_secs_f64(),
        random,
        ordered
    );
}
