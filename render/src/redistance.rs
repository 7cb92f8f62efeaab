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
//! 1. every voxel with a 6-neighbour of the other sign is a *seed*; its
//!    distance to the surface is estimated from the crossings on its grid
//!    edges, `t_a = f / (f − f_nb)` voxels along axis `a`, as the distance
//!    to the plane through them, `1 / sqrt(Σ 1/t_a²)` (the initialisation
//!    of the fast marching method, Sethian 1999, section 8.2);
//! 2. every other voxel gets the exact Euclidean distance to the nearest
//!    seed centre, by the separable squared-distance transform of
//!    Felzenszwalb and Huttenlocher (2012, "Distance transforms of sampled
//!    functions"), with the sign of its own value.
//!
//! Each surface point lies in a grid cell with a seed corner, so the result
//! is within about one voxel of the true distance on either side.

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;

use crate::bake::BakeError;

/// Steepest slope of the value across the surface (mm per mm) that is
/// still traced as it is: a distance has slope 1 there; a tiled lattice or
/// a TPMS sheet, not exact distances, stay close to it.
const MAX_SLOPE: f64 = 1.5;

/// Flattest typical slope traced as it is: below it the tracer's steps
/// shrink until it runs out of them before reaching the surface.
const MIN_SLOPE: f64 = 0.5;

/// Whether a baked field of a model that is not a distance bound must be
/// redistanced: its slope across the surface (between x-neighbours of
/// opposite sign) is steeper than [`MAX_SLOPE`] somewhere, or flatter than
/// [`MIN_SLOPE`] at most crossings. Tiled lattices and TPMS sheets pass as
/// they are, which keeps their sub-voxel struts (their values stay
/// distances to within the thin-feature bias the shader applies).
pub fn needs_redistance(field: &[f32], nx: usize, voxel: f32) -> bool {
    let h = voxel as f64;
    let (steepest, flat, crossings) = field
        .par_chunks(nx)
        .map(|row| {
            let mut acc = (0.0f64, 0usize, 0usize);
            for w in row.windows(2) {
                if (w[0] <= 0.0) != (w[1] <= 0.0) {
                    let slope = (w[1] as f64 - w[0] as f64).abs() / h;
                    // A non-finite value is steeper than any limit.
                    let slope = if slope.is_nan() { f64::INFINITY } else { slope };
                    acc.0 = acc.0.max(slope);
                    acc.1 += usize::from(slope < MIN_SLOPE);
                    acc.2 += 1;
                }
            }
            acc
        })
        .reduce(|| (0.0, 0, 0), |a, b| (a.0.max(b.0), a.1 + b.1, a.2 + b.2));
    crossings > 0 && (steepest > MAX_SLOPE || 2 * flat > crossings)
}

/// Squared distance (voxels²) standing for "no seed on this line yet".
const NONE: f64 = 1.0e30;

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
    let inside = |v: f32| v <= 0.0;
    // Seeds: sub-voxel distance in voxels; others NONE (as a square).
    let seed: Vec<f64> = {
        let f = &*field;
        (0..field.len())
            .into_par_iter()
            .map(|v| {
                let (i, j, k) = (v % nx, (v / nx) % ny, v / layer);
                let here = f[v];
                let mut sum = 0.0f64;
                let mut any = false;
                for (pos, n, stride) in [(i, nx, 1), (j, ny, nx), (k, nz, layer)] {
                    let mut t_min = f64::INFINITY;
                    for nb in [pos.checked_sub(1), Some(pos + 1).filter(|p| *p < n)]
                        .into_iter()
                        .flatten()
                    {
                        let there = f[v + nb * stride - pos * stride];
                        if inside(here) != inside(there) {
                            t_min = t_min.min(crossing(here, there));
                        }
                    }
                    if t_min.is_finite() {
                        any = true;
                        sum += 1.0 / (t_min * t_min).max(1e-12);
                    }
                }
                if any { 1.0 / sum } else { NONE }
            })
            .collect()
    };
    if cancel.load(Ordering::Relaxed) {
        return Err(BakeError::Cancelled);
    }
    // Squared distance to the nearest seed centre, seeds keeping their own.
    let mut sq: Vec<f64> = seed
        .iter()
        .map(|s| if *s < NONE { 0.0 } else { NONE })
        .collect();
    for (n, stride) in [(nx, 1), (ny, nx), (nz, layer)] {
        if cancel.load(Ordering::Relaxed) {
            return Err(BakeError::Cancelled);
        }
        transform_lines(&mut sq, n, stride);
    }
    let far = (nx * nx + ny * ny + nz * nz) as f64;
    field
        .par_iter_mut()
        .zip(sq.par_iter().zip(seed.par_iter()))
        .for_each(|(f, (d2, s))| {
            let voxels = if *s < NONE {
                s.sqrt()
            } else {
                d2.min(far).sqrt()
            };
            let d = (voxels * voxel as f64) as f32;
            *f = if inside(*f) { -d } else { d };
        });
    Ok(())
}

/// Where the zero lies between two values of opposite sign, in voxels from
/// the first (linear interpolation; 0.5 where a value is not finite).
fn crossing(here: f32, there: f32) -> f64 {
    let (a, b) = (here as f64, there as f64);
    let t = a / (a - b);
    if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.5
    }
}

/// The 1-D squared-distance transform along every line of `n` values with
/// `stride` between them.
fn transform_lines(sq: &mut [f64], n: usize, stride: usize) {
    let total = sq.len();
    let lines = total / n;
    // Line `l` starts at `base(l)`: lines are contiguous runs when
    // stride = 1, else `stride` interleaved lines per block of n·stride.
    let base = |l: usize| (l / stride) * n * stride + l % stride;
    let src = &*sq;
    let out: Vec<Vec<f64>> = (0..lines)
        .into_par_iter()
        .map_init(
            || (Vec::new(), Vec::new(), Vec::new()),
            |(line, v, z), l| {
                let b = base(l);
                line.clear();
                line.extend((0..n).map(|q| src[b + q * stride]));
                let mut d = vec![0.0; n];
                dt_1d(line, &mut d, v, z);
                d
            },
        )
        .collect();
    for (l, d) in out.into_iter().enumerate() {
        let b = base(l);
        for (q, x) in d.into_iter().enumerate() {
            sq[b + q * stride] = x;
        }
    }
}

/// Felzenszwalb–Huttenlocher: `d[q] = min_p (q − p)² + f[p]` by the lower
/// envelope of parabolas.
fn dt_1d(f: &[f64], d: &mut [f64], v: &mut Vec<usize>, z: &mut Vec<f64>) {
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
    for (q, out) in d.iter_mut().enumerate() {
        while z[k + 1] < q as f64 {
            k += 1;
        }
        let dq = q as f64 - v[k] as f64;
        *out = dq * dq + f[v[k]];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_dimension_matches_brute_force() {
        let f = [NONE, 0.0, NONE, NONE, 2.0, NONE, NONE, NONE, 0.0, NONE];
        let mut d = vec![0.0; f.len()];
        dt_1d(&f, &mut d, &mut Vec::new(), &mut Vec::new());
        for q in 0..f.len() {
            let want = (0..f.len())
                .map(|p| (q as f64 - p as f64).powi(2) + f[p])
                .fold(f64::INFINITY, f64::min);
            assert_eq!(d[q], want, "q = {q}");
        }
    }

    /// A sphere given as 100·(|p|² − r²): the redistanced field is within a
    /// voxel of |p| − r everywhere, with the sign of the value.
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
        let mut worst = 0.0f32;
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let p = glam::Vec3::new(c(i), c(j), c(k));
                    let got = field[i + n * (j + n * k)];
                    let want = p.length() - r;
                    assert_eq!(got <= 0.0, want <= 0.0, "sign at {p}");
                    worst = worst.max((got - want).abs());
                }
            }
        }
        assert!(worst <= h, "worst error {worst} mm for {h} mm voxels");
    }
}
