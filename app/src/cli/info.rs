//! `volcad info`, `volcad eval` and `volcad bench`.

use glam::DVec3;
use std::path::PathBuf;

use super::DesignArgs;
use super::design::load_design;

/// `volcad info DESIGN`.
pub fn info(args: &DesignArgs) -> anyhow::Result<()> {
    let l = load_design(args)?;
    let m = &l.model;
    let b = m.bbox();
    println!("design:      {}", args.design.display());
    println!("root:        {}", l.design.root.kind().type_name());
    println!("nodes:       {}", m.node_count());
    println!(
        "bbox (mm):   [{:.4}, {:.4}, {:.4}] .. [{:.4}, {:.4}, {:.4}]",
        b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z
    );
    let s = b.size();
    println!("size (mm):   {:.4} x {:.4} x {:.4}", s.x, s.y, s.z);
    let names: Vec<String> = m
        .materials()
        .iter()
        .map(|id| format!("{} ({id})", m.table().name(*id)))
        .collect();
    println!("materials:   {}", names.join(", "));
    println!("table:       {}", m.table().origin());
    for p in &l.design.params {
        println!(
            "param:       {} = {} (default {}, range {}..{})",
            p.name, p.value, p.default, p.min, p.max
        );
    }
    println!("script time: {:.3} s", l.script_time.as_secs_f64());
    println!("prepare:     {:.3} s", m.prepare_time().as_secs_f64());
    Ok(())
}

/// `volcad eval DESIGN X Y Z`.
pub fn eval(args: &DesignArgs, x: f64, y: f64, z: f64) -> anyhow::Result<()> {
    let l = load_design(args)?;
    let (d, fracs) = l.model.eval_point(DVec3::new(x, y, z));
    println!("distance: {d}");
    if fracs.is_empty() {
        println!("outside: no material");
    }
    for (id, f) in fracs {
        println!("{}: {f}", l.model.table().name(id));
    }
    Ok(())
}

/// `volcad bench` options.
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    /// Designs to measure (default: every example in assets/examples).
    pub designs: Vec<PathBuf>,
    /// Points per measurement.
    #[arg(long, default_value_t = 2_000_000)]
    pub points: usize,
}

/// `volcad bench`: points per second near the surface for each design.
pub fn bench(args: &BenchArgs) -> anyhow::Result<()> {
    let designs = if args.designs.is_empty() {
        let dir = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/examples"));
        let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "rhai"))
            .collect();
        v.sort();
        v
    } else {
        args.designs.clone()
    };
    println!(
        "{:<28} {:>8} {:>14} {:>16} {:>16}",
        "design", "nodes", "prepare (ms)", "random order", "Z-order"
    );
    for path in designs {
        let d = super::DesignArgs {
            design: path.clone(),
            params: vec![],
        };
        let l = match load_design(&d) {
            Ok(l) => l,
            Err(e) => {
                println!("{:<28} error: {e:#}", path.display());
                continue;
            }
        };
        let pts = volcad_core::bench::near_surface_points(&l.model, args.points, 2.0, 7);
        let pps = volcad_core::bench::points_per_second(&l.model, &pts);
        let sorted = volcad_core::bench::z_order(&l.model, &pts);
        let pps_z = volcad_core::bench::points_per_second(&l.model, &sorted);
        println!(
            "{:<28} {:>8} {:>14.1} {:>16.3e} {:>16.3e}",
            path.file_name()
                .map(|f| f.to_string_lossy().to_string())
                .unwrap_or_default(),
            l.model.node_count(),
            l.model.prepare_time().as_secs_f64() * 1e3,
            pps,
            pps_z
        );
    }
    Ok(())
}
