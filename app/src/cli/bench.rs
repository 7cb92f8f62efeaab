//! `volcad bench`.

use glam::DVec3;
use std::path::PathBuf;

use volcad_core::bench::{
    median_of_passes, median_points_per_second, near_surface_points, z_order,
};

use super::design::load_design;

/// `volcad bench` options.
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    /// Designs to measure (default: every example in assets/examples).
    pub designs: Vec<PathBuf>,
    /// Points per measurement.
    #[arg(long, default_value_t = 2_000_000, allow_negative_numbers = true)]
    pub points: usize,
    /// Voxels of each export grid: the voxel size per design is
    /// `cbrt(box volume / N)`.
    #[arg(long, default_value_t = 10_000_000, allow_negative_numbers = true)]
    pub voxels: u64,
    /// Measure evaluation only (no slice-stack and mesh exports).
    #[arg(long)]
    pub no_exports: bool,
    /// A folder the designs may also read, besides their projects
    /// (repeatable).
    #[arg(long = "allow-read", value_name = "DIR")]
    pub allow_read: Vec<PathBuf>,
}

/// `volcad bench`: points per second near the surface for each design
/// (the median of up to five passes, random and Z-ordered), then voxels
/// per second of its slice stack (random dither) and of its segmented
/// meshes (dominant material, STL + OBJ + 3MF), each the median of up to
/// three exports into a temporary folder that is removed.
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
    // What the figures are of: points/s depends on how densely the points
    // fill the band (docs/PERFORMANCE.md, "How to measure").
    outln!(
        "points/s: {} points within 2 mm of each design's surface, medians of up to 5 passes{}",
        args.points,
        if args.no_exports {
            String::new()
        } else {
            format!(
                "; voxels/s: exports of about {} voxels, medians of up to 3",
                args.voxels
            )
        }
    );
    // Which machine: figures differ by a factor of two between the
    // processors this project's machines have had (docs/PERFORMANCE.md).
    outln!("machine: {}", machine());
    outln!(
        "{:<28} {:>8} {:>14} {:>16} {:>16} {:>11} {:>14} {:>14}",
        "design",
        "nodes",
        "prepare (ms)",
        "random order",
        "Z-order",
        "voxel (mm)",
        "png voxels/s",
        "mesh voxels/s"
    );
    // A design that cannot be measured is a row and, at the end, a failure:
    // a script that benchmarks a missing file must not pass.
    let mut failed = Vec::new();
    for path in designs {
        let d = super::DesignArgs {
            design: path.clone(),
            params: vec![],
            allow_read: args.allow_read.clone(),
            params_file: None,
            set: None,
        };
        let l = match load_design(&d) {
            Ok(l) => l,
            Err(e) => {
                outln!("{:<28} error: {e:#}", path.display());
                failed.push(path.display().to_string());
                continue;
            }
        };
        let pts = near_surface_points(&l.model, args.points, 2.0, 7);
        // Median of up to five passes, about a second of them per figure.
        let budget = std::time::Duration::from_secs(1);
        let pps = median_points_per_second(&l.model, &pts, 5, budget);
        let sorted = z_order(&l.model, &pts);
        let pps_z = median_points_per_second(&l.model, &sorted, 5, budget);
        let exports = if args.no_exports {
            String::new()
        } else {
            export_rates(&l.model, args.voxels)
        };
        outln!(
            "{:<28} {:>8} {:>14.1} {:>16.3e} {:>16.3e}{exports}",
            path.file_name()
                .map(|f| f.to_string_lossy().to_string())
                .unwrap_or_default(),
            l.model.node_count(),
            l.model.prepare_time().as_secs_f64() * 1e3,
            pps,
            pps_z
        );
    }
    if !failed.is_empty() {
        anyhow::bail!(
            "{} design{} could not be measured: {}",
            failed.len(),
            if failed.len() == 1 { "" } else { "s" },
            failed.join(", ")
        );
    }
    Ok(())
}

/// The processor and the threads the figures use, as `volcad bench`
/// prints them: `/proc/cpuinfo`'s model name where there is one (Linux),
/// else the architecture.
fn machine() -> String {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| cpu_model(&s));
    let threads = rayon::current_num_threads();
    format!(
        "{}, {threads} thread{}",
        model.unwrap_or_else(|| std::env::consts::ARCH.to_string()),
        if threads == 1 { "" } else { "s" }
    )
}

/// The first `model name` in a `/proc/cpuinfo` text.
fn cpu_model(cpuinfo: &str) -> Option<String> {
    cpuinfo.lines().find_map(|l| {
        let (key, value) = l.split_once(':')?;
        (key.trim() == "model name" && !value.trim().is_empty()).then(|| value.trim().to_string())
    })
}

/// Export passes per figure: the median of up to three, as points/s takes
/// the median of its passes. A short export's single pass moves with a
/// scheduling hiccup or a slow batch of page faults; the median does not.
const EXPORT_PASSES: usize = 3;
/// Passes stop once this much time has gone into one figure (the slowest
/// exports take seconds a pass).
const EXPORT_BUDGET: std::time::Duration = std::time::Duration::from_secs(2);

/// The voxel size and the slice-stack and mesh export rates of `model` on
/// a grid of about `voxels` voxels, as table columns (or why not).
fn export_rates(model: &std::sync::Arc<volcad_core::Model>, voxels: u64) -> String {
    use volcad_compilers::job::{self, ExportError, JobContext, Summary};
    use volcad_compilers::mesh::{MeshParams, export_meshes};
    use volcad_compilers::png_stack::{PngParams, export_png_stack};

    type Work = Box<dyn FnOnce(&JobContext) -> Result<Summary, ExportError> + Send>;
    let size = model.bbox().size();
    let volume = size.x * size.y * size.z;
    if !(volume.is_finite() && volume > 0.0) {
        return format!(" {:>11}", "unbounded");
    }
    let voxel = (volume / voxels.max(1) as f64).cbrt();
    // Voxels per second of one export into a temporary folder, removed.
    let pass = |kind: &str, work: Work| {
        let dest = std::env::temp_dir().join(format!(
            "volcad-bench-{}-{kind}-{}",
            std::process::id(),
            next_id()
        ));
        let t = std::time::Instant::now();
        let r = job::spawn(dest.clone(), "bench".into(), work).join();
        let secs = t.elapsed().as_secs_f64();
        let _ = std::fs::remove_dir_all(&dest);
        r.map(|s| s.units as f64 / secs)
    };
    let figure = |kind: &str, make: &dyn Fn() -> Work| match median_of_passes(
        EXPORT_PASSES,
        EXPORT_BUDGET,
        || pass(kind, make()),
    ) {
        Ok(rate) => format!("{rate:>14.3e}"),
        Err(e) => format!(" {kind}: {e}"),
    };
    let png = PngParams {
        voxel: DVec3::splat(voxel),
        ..PngParams::default()
    };
    let mesh = MeshParams {
        voxel: DVec3::splat(voxel),
        ..MeshParams::default()
    };
    let png = figure("png", &|| {
        let (m, p) = (model.clone(), png.clone());
        Box::new(move |ctx| export_png_stack(&m, &p, ctx))
    });
    let mesh = figure("mesh", &|| {
        let (m, p) = (model.clone(), mesh.clone());
        Box::new(move |ctx| export_meshes(&m, &p, ctx))
    });
    format!(" {voxel:>11.4} {png} {mesh}")
}

/// A number that differs between calls (temporary folder names).
fn next_id() -> u64 {
    use std::sync::atomic::{AtomicU64, Ordering};
    static N: AtomicU64 = AtomicU64::new(0);
    N.fetch_add(1, Ordering::Relaxed)
}

#[cfg(test)]
mod tests {
    use super::cpu_model;

    #[test]
    fn the_processor_is_the_first_model_name() {
        let text = "processor\t: 0\nvendor_id\t: GenuineIntel\nmodel name\t: Intel(R) Xeon(R) Processor\n\
                    \nprocessor\t: 1\nmodel name\t: Other\n";
        assert_eq!(
            cpu_model(text).as_deref(),
            Some("Intel(R) Xeon(R) Processor")
        );
        // No model name (some ARM kernels), or an empty one: none.
        assert_eq!(cpu_model("processor\t: 0\nBogoMIPS\t: 50.00\n"), None);
        assert_eq!(cpu_model("model name\t:   \n"), None);
    }
}
