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
