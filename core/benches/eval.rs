//! Points per second near the surface (within 2 mm) for every example and
//! the 3,286-strut bunny lattice. `cargo bench -p volcad-core`.
//!
//! Plain timers (no criterion): one warm-up pass, then the best of three.

use std::path::PathBuf;

use volcad_core::Model;
use volcad_core::bench::{near_surface_points, points_per_second, z_order};
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
        let t = std::time::Instant::now();
        let d = match run_script(&src, &name, &ScriptOptions::for_file(&path)) {
            Ok(d) => d,
            Err(e) => {
                println!("{name:<26} error: {e}");
                continue;
            }
        };
        let script = t.elapsed().as_secs_f64();
        let m = Model::prepare(&d.root, d.materials.clone()).unwrap();
        let pts = near_surface_points(&m, 1_000_000, 2.0, 7);
        points_per_second(&m, &pts[..pts.len().min(100_000)]);
        let best = (0..3)
            .map(|_| points_per_second(&m, &pts))
            .fold(0.0, f64::max);
        let pts = z_order(&m, &pts);
        let ordered = (0..3)
            .map(|_| points_per_second(&m, &pts))
            .fold(0.0, f64::max);
        println!(
            "{name:<26} {:>7} {:>12.3} {:>12.4} {:>16.3e} {:>16.3e}",
            m.node_count(),
            script,
            m.prepare_time().as_secs_f64(),
            best,
            ordered
        );
    }
}
