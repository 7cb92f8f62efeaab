//! Measurement helpers shared by `cargo bench -p volcad-core` and
//! `volcad bench`: the same points and the same loop, so both report the
//! same figure.

use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use crate::Model;
pub use crate::xorshift::XorShift;

/// `n` points within `band` mm of the surface, uniformly distributed over
/// that band, drawn deterministically (xorshift from `seed`): the hard case
/// for evaluation (far points are cheap, and samplers cull them anyway).
/// The box is cut into 32³ equal cells and the cells whose distance
/// interval proves them outside the band are dropped; points are drawn
/// uniformly from the remaining cells and kept when `|d| ≤ band` (rejection
/// within equal cells keeps the distribution uniform, and skips the far
/// points whose exact distance is the slow part of drawing). Returns fewer
/// points if the band is too thin to find them.
pub fn near_surface_points(model: &Model, n: usize, band: f64, seed: u64) -> Vec<DVec3> {
    let b = model.bbox();
    let mut rng = crate::xorshift::XorShift::new(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let mut next = || rng.next_f64();
    const CELLS: usize = 32;
    let cell = b.size() / CELLS as f64;
    let near: Vec<DVec3> = (0..CELLS * CELLS * CELLS)
        .map(|i| {
            let (x, y, z) = (i % CELLS, i / CELLS % CELLS, i / (CELLS * CELLS));
            b.min + DVec3::new(x as f64, y as f64, z as f64) * cell
        })
        .filter(|lo| {
            let iv = model.interval(&crate::Aabb::new(*lo, *lo + cell));
            iv.lo <= band && iv.hi >= -band
        })
        .collect();
    let mut out = Vec::with_capacity(n);
    if near.is_empty() {
        return out;
    }
    let mut tries = 0usize;
    while out.len() < n && tries < n.saturating_mul(400) {
        tries += 1;
        let k = ((next() * near.len() as f64) as usize).min(near.len() - 1);
        let p = near[k] + DVec3::new(next(), next(), next()) * cell;
        if model.distance(p).abs() <= band {
            out.push(p);
        }
    }
    out
}

/// Distance and fractions at every point, on all rayon threads; returns
/// points per second.
pub fn points_per_second(model: &Model, pts: &[DVec3]) -> f64 {
    let k = model.materials().len();
    let start = Instant::now();
    let sum: f64 = pts
        .par_chunks(4096)
        .map(|chunk| {
            let mut f = vec![0.0; k];
            let mut acc = 0.0;
            for p in chunk {
                acc += model.eval_into(*p, &mut f) + f[0];
            }
            acc
        })
        .sum();
    std::hint::black_box(sum);
    pts.len() as f64 / start.elapsed().as_secs_f64()
}

/// Steady-state [`points_per_second`]: one warm-up pass over the first
/// tenth of `pts` (it faults in the model's lazily touched pages and wakes
/// the threads), then passes until `max_passes` are done or `budget` is
/// spent (at least one), and the median of those. A single pass of 2 M
/// points lasts about a tenth of a second here, short enough for one
/// scheduling hiccup to move it by a fifth; the median of five does not
/// follow one bad pass.
pub fn median_points_per_second(
    model: &Model,
    pts: &[DVec3],
    max_passes: usize,
    budget: std::time::Duration,
) -> f64 {
    points_per_second(model, &pts[..pts.len().div_ceil(10)]);
    let rate = median_of_passes(max_passes, budget, || {
        Ok::<_, std::convert::Infallible>(points_per_second(model, pts))
    });
    rate.unwrap_or_else(|e| match e {})
}

/// The median of `pass`'s figures over passes until `max_passes` are done
/// or `budget` is spent (at least one); the first error stops and is
/// returned. `volcad bench` takes its export figures this way too.
pub fn median_of_passes<E>(
    max_passes: usize,
    budget: std::time::Duration,
    mut pass: impl FnMut() -> Result<f64, E>,
) -> Result<f64, E> {
    let start = Instant::now();
    let mut rates = Vec::with_capacity(max_passes);
    while rates.is_empty() || (rates.len() < max_passes && start.elapsed() < budget) {
        rates.push(pass()?);
    }
    rates.sort_by(f64::total_cmp);
    Ok(rates[rates.len() / 2])
}

/// The same points in Z-order (Morton order of their position in the
/// model's box, 1/1024 of it per step): the order in which samplers, the
/// baker and the ray marcher visit space, neighbours after neighbours.
/// `points_per_second` on random order measures memory latency as much as
/// evaluation; both figures are reported.
pub fn z_order(model: &Model, pts: &[DVec3]) -> Vec<DVec3> {
    let b = model.bbox();
    let size = b.size().max(DVec3::splat(1e-9));
    let spread = |v: u64| {
        // 10 bits → every third bit of 30.
        let mut x = v & 0x3ff;
        x = (x | (x << 16)) & 0x0300_00ff;
        x = (x | (x << 8)) & 0x0300_f00f;
        x = (x | (x << 4)) & 0x030c_30c3;
        (x | (x << 2)) & 0x0924_9249
    };
    let key = |p: &DVec3| {
        let q = ((*p - b.min) / size * 1023.0).clamp(DVec3::ZERO, DVec3::splat(1023.0));
        spread(q.x as u64) | (spread(q.y as u64) << 1) | (spread(q.z as u64) << 2)
    };
    let mut keyed: Vec<(u64, DVec3)> = pts.iter().map(|p| (key(p), *p)).collect();
    keyed.sort_by_key(|k| k.0);
    keyed.into_iter().map(|k| k.1).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::script::{ScriptOptions, run_script};

    #[test]
    fn band_points_fill_the_band_evenly() {
        let src = r#"let m = default_materials(); Sphere(Vec3(0,0,0), 10, m.id("red"))"#;
        let d = run_script(src, "t", &ScriptOptions::default()).unwrap();
        let m = Model::prepare(&d.root, d.materials).unwrap();
        let pts = near_surface_points(&m, 20_000, 2.0, 7);
        assert_eq!(pts.len(), 20_000);
        assert!(pts.iter().all(|p| m.distance(*p).abs() <= 2.0));
        // Uniform over the band clipped to the box [−10, 10]³: the part
        // inside the sphere (8 < r < 10) holds 48.2 % of that volume (Monte
        // Carlo with 2 million points).
        let inner = pts.iter().filter(|p| p.length() < 10.0).count() as f64 / 2e4;
        assert!((inner - 0.482).abs() < 0.015, "{inner}");
        // A rate from one pass when the budget is spent at once, and the
        // median of the passes otherwise: positive and finite both ways.
        for budget in [0, 1] {
            let r = median_points_per_second(&m, &pts, 3, std::time::Duration::from_secs(budget));
            assert!(r.is_finite() && r > 0.0, "{r}");
        }
        // Same seed, same points.
        assert_eq!(pts[..10], near_surface_points(&m, 10, 2.0, 7)[..]);
    }

    #[test]
    fn passes_give_their_median_within_the_budget() {
        use std::time::Duration;
        let figures = [5.0, 1.0, 9.0, 3.0, 7.0];
        let mut next = figures.iter().copied();
        let r = median_of_passes(5, Duration::from_secs(60), || next.next().ok_or("none"));
        assert_eq!(r, Ok(5.0));
        // A spent budget: one pass.
        let mut n = 0;
        let r = median_of_passes(5, Duration::ZERO, || {
            n += 1;
            Ok::<_, ()>(2.0)
        });
        assert_eq!((r, n), (Ok(2.0), 1));
        // The first error stops the passes.
        let mut n = 0;
        let r = median_of_passes(5, Duration::from_secs(60), || {
            n += 1;
            if n == 2 { Err("disk full") } else { Ok(1.0) }
        });
        assert_eq!((r, n), (Err("disk full"), 2));
    }
}
