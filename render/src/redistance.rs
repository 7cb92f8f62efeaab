//! Turn a baked field that is not a distance into one that is, so the
//! sphere tracer (and every view mode that reads millimetres from the
//! distance volume) can use it.
//!
//! A math-string `Function` (a quartic handle, say) has the right sign but
//! not the right size: far from the surface it can be thousands of times
//! the distance, so a tracer stepping by it jumps over the part, and where
//! it is much smaller the tracer runs out of steps. Only the sign and the
//! zero crossings are trusted here:
//!
//! 1. every voxel with one of its 26 neighbours of the other sign is a
//!    *seed*, with an estimate of its nearest surface point: the Newton
//!    step `−f ∇f / |∇f|²` (central differences) where the field is smooth
//!    enough for it to stay near the voxel, else the nearest point of the
//!    plane through the crossings on its edges, `t_a = f / (f − f_nb)`
//!    voxels along axis `a`: at `n / |n|²` from its centre with
//!    `n = Σ ±e_a / t_a` (the fast marching method's initialisation,
//!    Sethian 1999, section 8.2);
//! 2. the separable squared-distance transform of Felzenszwalb and
//!    Huttenlocher (2012, "Distance transforms of sampled functions"),
//!    carrying which seed each minimum came from, finds every voxel's
//!    nearest seed; its value is the distance to that seed's surface point
//!    (a closest-point transform; within two voxels of a seed, the nearest
//!    of its neighbours' seeds' points), with the sign of its own value.
//!
//! The field is then within a fraction of a voxel of the true distance and
//! varies smoothly, so normals taken from it shade smoothly.

use std::sync::atomic::{AtomicBool, Ordering};

use glam::Vec3;
use rayon::prelude::*;

use crate::bake::BakeError;

/// Steepest slope of the value across the surface (mm per mm) that is
/// still traced as it is: a distance has slope at most 1; tiled lattices
/// and TPMS sheets, not exact distances, stay at or below it too.
const MAX_SLOPE: f64 = 1.5;

/// Whether a baked field of a model that is not a distance bound must be
/// redistanced: its slope across the surface (between x-neighbours of
/// opposite sign, a lower bound of the gradient's size) is steeper than
/// [`MAX_SLOPE`] somewhere, so a tracer stepping by it would overshoot.
/// Tiled lattices and TPMS sheets pass as they are, which keeps their
/// sub-voxel struts and walls and their bake time.
pub fn needs_redistance(field: &[f32], nx: usize, voxel: f32) -> bool {
    let h = voxel as f64;
    field.par_chunks(nx).any(|row| {
        row.windows(2).any(|w| {
            let slope = (w[1] as f64 - w[0] as f64).abs() / h;
            // A non-finite difference counts as steep.
            (w[0] <= 0.0) != (w[1] <= 0.0) && (slope > MAX_SLOPE || slope.is_nan())
        })
    })
}

/// Squared distance (voxels²) standing for "no seed on this line yet".
const NONE: f32 = 1.0e30;

/// No nearest seed.
const NO_SEED: u32 = u32::MAX;

/// Within this many voxels of a seed (where shading reads the field) a
/// voxel also tries its 26 neighbours' seeds: the nearest seed centre is
/// not always the seed with the nearest surface point.
const BAND: f32 = 2.0;

/// Replace `field` (values at voxel centres, voxel `i + nx·(j + ny·k)`,
/// inside ⇔ ≤ 0, NaN counted as outside) by signed distances in mm for
/// voxels of edge `voxel` mm.
pub fn redistance(
    field: &mut [f32],
    dims: [usize; 3],
    voxel: f32,
    cancel: &AtomicBool,
) -> Result<(), BakeError> {
    let [nx, ny, nz] = dims;
    let layer = nx * ny;
    let n = field.len();
    if n > NO_SEED as usize {
        // Seed slots are u32; bakes are far below 2³² voxels.
        return Ok(());
    }
    let f = &*field;
    let centre = |v: usize| Vec3::new((v % nx) as f32, ((v / nx) % ny) as f32, (v / layer) as f32);
    // Each seed's voxel and its estimate of the surface point (voxels).
    let seeds: Vec<(u32, Vec3)> = (0..n)
        .into_par_iter()
        .filter_map(|v| surface_offset(f, dims, v).map(|o| (v as u32, centre(v) + o)))
        .collect();
    if cancel.load(Ordering::Relaxed) {
        return Err(BakeError::Cancelled);
    }
    // Squared distance (voxels²) to the nearest seed centre, and that
    // seed's index in `seeds`.
    let mut sq = vec![NONE; n];
    let mut feat = vec![NO_SEED; n];
    for (slot, (v, _)) in seeds.iter().enumerate() {
        sq[*v as usize] = 0.0;
        feat[*v as usize] = slot as u32;
    }
    for (len, stride) in [(nx, 1), (ny, nx), (nz, layer)] {
        if cancel.load(Ordering::Relaxed) {
            return Err(BakeError::Cancelled);
        }
        transform_lines(&mut sq, &mut feat, len, stride);
    }
    let far = ((nx * nx + ny * ny + nz * nz) as f32).sqrt() * voxel;
    let to_surface = |v: usize, s: u32| (centre(v) - seeds[s as usize].1).length();
    let (sq, feat) = (&sq, &feat);
    let out: Vec<f32> = (0..n)
        .into_par_iter()
        .map(|v| {
            let d = match feat[v] {
                NO_SEED => far,
                s if sq[v] > BAND * BAND => to_surface(v, s) * voxel,
                s => nearest_in_band(v, s, dims, feat, to_surface) * voxel,
            };
            if f[v] <= 0.0 { -d } else { d }
        })
        .collect();
    field.copy_from_slice(&out);
    Ok(())
}

/// The distance (voxels) from voxel `v` to the nearest surface point among
/// those of its own seed `s` and of its 26 neighbours' seeds.
fn nearest_in_band(
    v: usize,
    s: u32,
    dims: [usize; 3],
    feat: &[u32],
    to_surface: impl Fn(usize, u32) -> f32,
) -> f32 {
    let [nx, ny, nz] = dims;
    let layer = nx * ny;
    let (i, j, k) = (v % nx, (v / nx) % ny, v / layer);
    let mut best = to_surface(v, s);
    let mut seen = [s; 27];
    let mut count = 1;
    for kk in k.saturating_sub(1)..(k + 2).min(nz) {
        for jj in j.saturating_sub(1)..(j + 2).min(ny) {
            for ii in i.saturating_sub(1)..(i + 2).min(nx) {
                let t = feat[ii + nx * (jj + ny * kk)];
                if t != NO_SEED && !seen[..count].contains(&t) {
                    seen[count] = t;
                    count += 1;
                    best = best.min(to_surface(v, t));
                }
            }
        }
    }
    best
}

/// For a voxel with a neighbour (of 26) of the other sign, the offset
/// (voxels) from its centre to its estimate of the nearest surface point;
/// `None` for any other voxel. The estimate is the Newton step `−f ∇f / |∇f|²` with
/// the central-difference gradient where that lands within the voxel's
/// neighbourhood (a smooth field), else the nearest point of the plane
/// through the crossings on its edges.
fn surface_offset(f: &[f32], dims: [usize; 3], v: usize) -> Option<Vec3> {
    let [nx, ny, nz] = dims;
    let layer = nx * ny;
    let (i, j, k) = (v % nx, (v / nx) % ny, v / layer);
    let here = f[v];
    let inside = here <= 0.0;
    let mut n = Vec3::ZERO;
    let mut grad = Vec3::ZERO;
    for (axis, (pos, len, stride)) in [(i, nx, 1), (j, ny, nx), (k, nz, layer)]
        .into_iter()
        .enumerate()
    {
        let lo = (pos > 0).then(|| f[v - stride]);
        let hi = (pos + 1 < len).then(|| f[v + stride]);
        grad[axis] = match (lo, hi) {
            (Some(a), Some(b)) => 0.5 * (b - a),
            (Some(a), None) => here - a,
            (None, Some(b)) => b - here,
            (None, None) => 0.0,
        };
        // The nearer crossing along this axis, with its direction.
        let mut best: Option<(f32, f32)> = None;
        for (dir, there) in [(-1.0f32, lo), (1.0, hi)] {
            if let Some(there) = there.filter(|t| (*t <= 0.0) != inside) {
                let t = crossing(here, there).max(1e-3);
                if best.is_none_or(|(bt, _)| t < bt) {
                    best = Some((t, dir));
                }
            }
        }
        if let Some((t, dir)) = best {
            n[axis] = dir / t;
        }
    }
    let len2 = n.length_squared();
    if len2 == 0.0 && !diagonal_crossing(f, dims, v) {
        return None;
    }
    let newton = -here * grad / grad.length_squared();
    if newton.is_finite() && newton.length() <= 1.75 {
        Some(newton)
    } else {
        (len2 > 0.0).then(|| n / len2)
    }
}

/// Whether any of the 26 neighbours of `v` has the other sign (a surface
/// passing a corner of the voxel: such voxels are seeds too, so points
/// near it take its Newton estimate instead of a farther seed's).
fn diagonal_crossing(f: &[f32], dims: [usize; 3], v: usize) -> bool {
    let [nx, ny, nz] = dims;
    let layer = nx * ny;
    let (i, j, k) = (v % nx, (v / nx) % ny, v / layer);
    let inside = f[v] <= 0.0;
    (k.saturating_sub(1)..(k + 2).min(nz)).any(|kk| {
        (j.saturating_sub(1)..(j + 2).min(ny)).any(|jj| {
            (i.saturating_sub(1)..(i + 2).min(nx))
                .any(|ii| (f[ii + nx * (jj + ny * kk)] <= 0.0) != inside)
        })
    })
}

/// Where the zero lies between two values of opposite sign, in voxels from
/// the first (linear interpolation; 0.5 where a value is not finite).
fn crossing(here: f32, there: f32) -> f32 {
    let (a, b) = (here as f64, there as f64);
    let t = a / (a - b);
    if t.is_finite() {
        t.clamp(0.0, 1.0) as f32
    } else {
        0.5
    }
}

/// The 1-D squared-distance transform along every line of `len` values with
/// `stride` between them, carrying the nearest seed in `feat`.
fn transform_lines(sq: &mut [f32], feat: &mut [u32], len: usize, stride: usize) {
    let lines = sq.len() / len;
    // Line `l` starts at `base(l)`: lines are contiguous runs when
    // stride = 1, else `stride` interleaved lines per block of len·stride.
    let base = |l: usize| (l / stride) * len * stride + l % stride;
    let (src, src_feat) = (&*sq, &*feat);
    let out: Vec<(Vec<f32>, Vec<u32>)> = (0..lines)
        .into_par_iter()
        .map_init(
            || (Vec::new(), Vec::new(), Vec::new(), Vec::new()),
            |(line, from, v, z), l| {
                let b = base(l);
                line.clear();
                line.extend((0..len).map(|q| src[b + q * stride] as f64));
                from.resize(len, 0);
                let mut d = vec![0.0f32; len];
                dt_1d(line, &mut d, from, v, z);
                let f = from.iter().map(|p| src_feat[b + p * stride]).collect();
                (d, f)
            },
        )
        .collect();
    for (l, (d, f)) in out.into_iter().enumerate() {
        let b = base(l);
        for (q, (x, s)) in d.into_iter().zip(f).enumerate() {
            sq[b + q * stride] = x;
            feat[b + q * stride] = s;
        }
    }
}

/// Felzenszwalb–Huttenlocher: `d[q] = min_p (q − p)² + f[p]` by the lower
/// envelope of parabolas; `from[q]` is the minimising p.
fn dt_1d(f: &[f64], d: &mut [f32], from: &mut [usize], v: &mut Vec<usize>, z: &mut Vec<f64>) {
    let n = f.len();
    v.clear();
    z.clear();
    v.push(0);
    z.push(f64::NEG_INFINITY);
    z.push(f64::INFINITY);
    let meet = |q: usize, p: usize| {
        let (qf, pf) = (q as f64, p as f64);
        ((f[q] + qf * qf) - (f[p] + pf * pf)) / (2.0 * (qf - pf))
    };
    for q in 1..n {
        let mut s = meet(q, v[v.len() - 1]);
        while v.len() > 1 && s <= z[v.len() - 1] {
            v.pop();
            z.pop();
            s = meet(q, v[v.len() - 1]);
        }
        // z holds one boundary more than v: replace the trailing +inf.
        let last = z.len() - 1;
        z[last] = s;
        v.push(q);
        z.push(f64::INFINITY);
    }
    let mut k = 0;
    for q in 0..n {
        while z[k + 1] < q as f64 {
            k += 1;
        }
        let dq = q as f64 - v[k] as f64;
        d[q] = (dq * dq + f[v[k]]).min(NONE as f64) as f32;
        from[q] = v[k];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_dimension_matches_brute_force() {
        let none = NONE as f64;
        let f = [none, 0.0, none, none, 2.0, none, none, none, 0.0, none];
        let mut d = vec![0.0; f.len()];
        let mut from = vec![0; f.len()];
        dt_1d(&f, &mut d, &mut from, &mut Vec::new(), &mut Vec::new());
        for q in 0..f.len() {
            let want = (0..f.len())
                .map(|p| (q as f64 - p as f64).powi(2) + f[p])
                .fold(f64::INFINITY, f64::min);
            assert_eq!(d[q] as f64, want, "q = {q}");
            let p = from[q];
            assert_eq!(
                (q as f64 - p as f64).powi(2) + f[p],
                want,
                "q = {q}: from {p}"
            );
        }
    }

    /// A sphere given as 100·(|p|² − r²): the redistanced field is within a
    /// tenth of a voxel of |p| − r near the surface and half a voxel
    /// everywhere, with the sign of the value.
    #[test]
    fn a_scaled_quadric_becomes_its_distance() {
        let (n, h, r) = (40usize, 0.25f32, 3.0f32);
        let c = |i: usize| (i as f32 + 0.5) * h - n as f32 * h / 2.0;
        let mut field = Vec::with_capacity(n * n * n);
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let p = glam::Vec3::new(c(i), c(j), c(k));
                    field.push(100.0 * (p.length_squared() - r * r));
                }
            }
        }
        redistance(&mut field, [n, n, n], h, &AtomicBool::new(false)).expect("not cancelled");
        let (mut worst, mut worst_near) = (0.0f32, 0.0f32);
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let p = glam::Vec3::new(c(i), c(j), c(k));
                    let got = field[i + n * (j + n * k)];
                    let want = p.length() - r;
                    assert_eq!(got <= 0.0, want <= 0.0, "sign at {p}");
                    worst = worst.max((got - want).abs());
                    if want.abs() < 1.5 * h {
                        worst_near = worst_near.max((got - want).abs());
                    }
                }
            }
        }
        eprintln!("worst error {worst} mm, {worst_near} mm near the surface, for {h} mm voxels");
        assert!(worst_near <= 0.1 * h, "near the surface: {worst_near} mm");
        assert!(worst <= 0.5 * h, "worst error {worst} mm");
    }

    /// Steep fields are redistanced, distances (and flatter fields) not.
    #[test]
    fn only_steep_fields_are_redistanced() {
        let (n, h) = (16usize, 0.5f32);
        let grid = |f: &dyn Fn(glam::Vec3) -> f32| -> Vec<f32> {
            let c = |i: usize| (i as f32 + 0.5) * h - n as f32 * h / 2.0;
            let mut out = Vec::new();
            for k in 0..n {
                for j in 0..n {
                    for i in 0..n {
                        out.push(f(glam::Vec3::new(c(i), c(j), c(k))));
                    }
                }
            }
            out
        };
        let distance = grid(&|p| p.length() - 2.0);
        let quartic = grid(&|p| (p.length_squared() - 4.0).powi(2) * (p.length() - 2.0).signum());
        let gentle = grid(&|p| 0.3 * (p.length() - 2.0));
        assert!(!needs_redistance(&distance, n, h));
        assert!(needs_redistance(&quartic, n, h));
        assert!(!needs_redistance(&gentle, n, h));
    }
}
