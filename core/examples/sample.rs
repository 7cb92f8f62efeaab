//! Embedding volcad-core: load a design, prepare it, and sample its
//! material fractions (and its first attribute, if it has one) on a small
//! grid into buffers this program owns, then print a summary.
//!
//! ```text
//! cargo run -p volcad-core --example sample -- assets/examples/graded_bar.rhai [VOXELS]
//! ```
//!
//! `VOXELS` (default 32) is the number of voxels along the design's
//! longest side.

use std::error::Error;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use volcad_core::{Consumer, DVec3, Grid, Model, Points, Sampler, Slab, model_of_file};

/// Layers sampled per call: the slab (and so memory) stays this thin
/// whatever the grid's height.
const LAYERS: usize = 4;

/// What the grid held, summed slab by slab.
#[derive(Default)]
struct Summary {
    /// Voxels inside the part.
    inside: usize,
    /// Each material's fractions summed over the inside voxels.
    fractions: Vec<f64>,
    /// Lowest and highest value of the attribute's first component, and
    /// the voxels that had one.
    attribute: Option<(f64, f64, usize)>,
}

fn main() -> std::process::ExitCode {
    match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// Read the arguments, load and prepare the design, sample it, and print
/// the summary.
fn run() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../assets/examples/graded_bar.rhai"),
        PathBuf::from,
    );
    let voxels: f64 = match args.next() {
        Some(n) => n.parse().map_err(|e| format!("VOXELS {n:?}: {e}"))?,
        None => 32.0,
    };
    if !(1.0..=1024.0).contains(&voxels) {
        return Err(format!("VOXELS must be 1 to 1024, got {voxels}").into());
    }
    let model = model_of_file(&path)?;
    let bbox = model.bbox();
    let voxel = bbox.size().max_element() / voxels;
    let grid = Grid::covering(&bbox, DVec3::splat(voxel), 1 << 24)?;
    let summary = sample(&model, grid)?;
    print_summary(&path, &model, grid, &summary);
    Ok(())
}

/// Sample every layer of `grid`, `LAYERS` at a time, into one reused
/// [`Slab`], and sum what it holds.
fn sample(model: &Model, grid: Grid) -> Result<Summary, Box<dyn Error>> {
    let [nx, ny, nz] = grid.dims;
    let k = model.materials().len();
    let sampler = Sampler::new(model, grid, Consumer::ViewportBake);
    let mut slab = Slab::default();
    let cancel = AtomicBool::new(false);
    let attribute = model.attributes().first().map(|a| (a.kind.width(), 0));
    let mut sum = Summary {
        fractions: vec![0.0; k],
        ..Summary::default()
    };
    // The inside voxels' centres of one slab, and the attribute there.
    let (mut xs, mut ys, mut zs, mut values) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut z0 = 0;
    while z0 < nz {
        let z1 = (z0 + LAYERS).min(nz);
        sampler.sample_layers(z0, z1, &mut slab, &cancel)?;
        xs.clear();
        ys.clear();
        zs.clear();
        for (v, d) in slab.dist.iter().enumerate() {
            if *d > 0.0 {
                continue;
            }
            sum.inside += 1;
            for (s, f) in sum.fractions.iter_mut().zip(slab.fracs_of(v)) {
                *s += f64::from(*f);
            }
            let c = grid.center(v % nx, (v / nx) % ny, z0 + v / (nx * ny));
            xs.push(c.x);
            ys.push(c.y);
            zs.push(c.z);
        }
        if let Some((width, index)) = attribute {
            values.resize(xs.len() * width, 0.0);
            let pts = Points {
                x: &xs,
                y: &ys,
                z: &zs,
            };
            model.attribute_batch(index, pts, &mut values)?;
            for v in values
                .chunks_exact(width)
                .map(|v| v[0])
                .filter(|v| v.is_finite())
            {
                let (lo, hi, n) = sum.attribute.get_or_insert((v, v, 0));
                (*lo, *hi, *n) = (lo.min(v), hi.max(v), *n + 1);
            }
        }
        z0 = z1;
    }
    Ok(sum)
}

/// One line each: the design, the grid, the volume inside, each
/// material's mean fraction there, and the attribute's range.
fn print_summary(path: &std::path::Path, model: &Model, grid: Grid, sum: &Summary) {
    let [nx, ny, nz] = grid.dims;
    let cell = grid.voxel.x * grid.voxel.y * grid.voxel.z;
    println!("design:    {}", path.display());
    println!(
        "grid:      {nx} x {ny} x {nz} voxels of {:.4} mm",
        grid.voxel.x
    );
    println!(
        "inside:    {} voxels, {:.3} mm³",
        sum.inside,
        sum.inside as f64 * cell
    );
    for (id, s) in model.materials().iter().zip(&sum.fractions) {
        let name = model.table().name(*id);
        println!(
            "fraction:  {name:<12} {:.4} mean inside",
            s / sum.inside.max(1) as f64
        );
    }
    match (model.attributes().first(), sum.attribute) {
        (Some(a), Some((lo, hi, n))) => {
            println!(
                "attribute: {} from {lo:.4} to {hi:.4} at {n} voxels",
                a.name
            )
        }
        (Some(a), None) => println!("attribute: {} has no value inside", a.name),
        (None, _) => println!("attribute: none"),
    }
}
