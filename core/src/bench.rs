//! Measurement helpers shared by `cargo bench -p volcad-core` and
//! `volcad bench`: the same points and the same loop, so both report the
//! same figure.

use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use crate::Model;

/// `n` points within `band` mm of the surface, drawn deterministically
/// (xorshift from `seed`) from the bounding box by rejection: the hard case
/// for evaluation (far points are cheap, and samplers cull them anyway).
/// Returns fewer points if the band is too thin to find them.
pub fn near_surface_points(model: &Model, n: usize, band: f64, seed: u64) -> Vec<DVec3> {
    let b = model.bbox();
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut out = Vec::with_capacity(n);
    let mut tries = 0usize;
    while out.len() < n && tries < n.saturating_mul(400) {
        tries += 1;
        let p = b.min + DVec3::new(next(), next(), next()) * b.size();
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
