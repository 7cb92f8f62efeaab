//! An open leaf tile, voxel by voxel: what [`Sampler::tile`] leaves when
//! no bound settles a tile of at most `LEAF × LEAF` voxels.
//!
//! Where the model's value is 1-Lipschitz (`Model::distance_is_bound`) and
//! the consumer allows it ([`super::consumer::Needs`]), each evaluated
//! voxel `v` settles the later voxels `u` of the leaf that it proves beyond
//! the margin (for a mesh export, one voxel diagonal; see `leaf`):
//! `|d(u)| ≥ |d(v)| − |u − v| > margin`, so `d(u)` has `d(v)`'s
//! sign and that lower bound is stored, as a tile beyond the margin stores
//! its interval's end (see the module docs of [`super`]). Their fractions
//! are written as an evaluation would write them (zero outside, where the
//! consumer reads them; inside, the tile's shared fractions), and an
//! inside voxel whose fractions are
//! not known without evaluating is evaluated.

use super::slab::{Rect, Rows, fill_pattern, fill_short};
use super::{LEAF, Sampler, Shared};
use crate::aabb::Aabb;
use crate::model::MAX_MATERIALS;

/// Distances between the voxel centres of a leaf, by offset `|dx| + LEAF·dy`.
pub(super) type LeafGaps = [f64; LEAF * LEAF];

/// [`LeafGaps`] for voxels of size `hx × hy`.
pub(super) fn leaf_gaps(hx: f64, hy: f64) -> LeafGaps {
    std::array::from_fn(|o| {
        let (dx, dy) = ((o % LEAF) as f64, (o / LEAF) as f64);
        (dx * hx).hypot(dy * hy)
    })
}

impl Sampler<'_> {
    /// Evaluate the open leaf `r` (voxel centres `b`) into `out`.
    pub(super) fn leaf(&self, r: Rect, out: &mut Rows, shared: &mut Shared, b: &Aabb) {
        let (z, x0, y0, w, h) = r.parts();
        let (k, row0, nx) = (out.k, out.row0, self.grid.dims[0]);
        // (Zeroed only where fractions are evaluated.)
        let mut f = None;
        // A lazy consumer bounds the fractions itself, run by run. Where
        // fractions are averages (a `Blend`, 125 or 216 child samples a voxel) and
        // their bounds over the tile are narrow, the inside voxels of tiles
        // a surface crosses get `NaN` fractions too, and only their
        // distance is evaluated (a large saving on the csg_tour slice
        // stack). For other designs the bound costs about what it saves.
        let lazy = k > 0 && self.lazy_open && self.bounded(b, k);
        // What an inside voxel gets without evaluating its fractions, once
        // known: `NaN` for the lazy consumer, or the shared fractions.
        let mut inside = match shared {
            _ if k == 0 => None,
            _ if lazy => Some([f32::NAN; MAX_MATERIALS]),
            Shared::Constant(one) => *one,
            Shared::Unknown => None,
        };
        let capture = matches!(shared, Shared::Constant(None));
        let (mut spared, mut settled) = (0, 0);
        // Lower bounds of later voxels' |d| (with their sign), or NaN.
        let mut bounds = [f32::NAN; LEAF * LEAF];
        // A mesh export's leaf settles only voxels it proves beyond one voxel
        // diagonal, though its tiles settle beyond zero: most voxels of an
        // open leaf nearer than that are corners of cut cubes, which the
        // contourer would evaluate one by one, without the leaf's order.
        let margin = self.unevaluated_near.unwrap_or_else(|| self.margin());
        for y in y0..y0 + h {
            let row = (y - row0) * nx;
            for x in x0..x0 + w {
                let v = row + x;
                let at = (y - y0) * LEAF + (x - x0);
                let bound = bounds[at];
                if bound > 0.0 || (bound <= 0.0 && (k == 0 || inside.is_some())) {
                    out.dist[v] = bound;
                    let voxel = &mut out.fracs[v * k..(v + 1) * k];
                    match &inside {
                        Some(one) if bound <= 0.0 => fill_pattern(voxel, &one[..k]),
                        _ if self.outside_fracs => fill_short(voxel, 0.0),
                        _ => {}
                    }
                    settled += 1;
                    continue;
                }
                let p = self.grid.center(x, y, z);
                let d = if let Some(one) = &inside {
                    let d = self.model.distance(p);
                    let voxel = &mut out.fracs[v * k..(v + 1) * k];
                    if d <= 0.0 {
                        fill_pattern(voxel, &one[..k]);
                        spared += 1;
                    } else if self.outside_fracs {
                        fill_short(voxel, 0.0);
                    }
                    d
                } else if k > 0 {
                    // (Lazily: the array's zeroing stays out of the loop.)
                    #[allow(clippy::unnecessary_lazy_evaluations)]
                    let f = f.get_or_insert_with(|| [0.0f64; MAX_MATERIALS]);
                    let d = self.model.eval_into(p, &mut f[..k]);
                    for (o, val) in out.fracs[v * k..(v + 1) * k].iter_mut().zip(&f[..k]) {
                        *o = *val as f32;
                    }
                    if capture && d <= 0.0 {
                        // The first inside voxel: the rest share its fractions.
                        let mut one = [0.0; MAX_MATERIALS];
                        for (o, val) in one.iter_mut().zip(&f[..k]) {
                            *o = *val as f32;
                        }
                        inside = Some(one);
                        *shared = Shared::Constant(inside);
                    }
                    d
                } else {
                    self.model.distance(p)
                };
                out.dist[v] = d as f32;
                if self.lipschitz_skip {
                    self.bound_later(d, margin, at, [w, h], &mut bounds);
                }
            }
        }
        out.counts.evaluated += (w * h - settled) as u64;
        out.counts.skipped += settled as u64;
        if !lazy {
            out.counts.shared += spared;
        }
    }

    /// Bound the leaf's voxels after `at` (of `w × h`) by the value `d`
    /// at `at`, where that proves them beyond `margin`.
    fn bound_later(&self, d: f64, margin: f64, at: usize, [w, h]: [usize; 2], bounds: &mut [f32]) {
        let a = d.abs();
        // Nothing is proved when not even the nearest neighbour is reached
        // (nor by a NaN value).
        if a.is_nan() || a <= margin + self.leaf_gaps[1].min(self.leaf_gaps[LEAF]) {
            return;
        }
        let (ix, iy) = (at % LEAF, at / LEAF);
        for jy in iy..h {
            for jx in 0..w {
                let j = jy * LEAF + jx;
                if j <= at || !bounds[j].is_nan() {
                    continue;
                }
                let m = a - self.leaf_gaps[ix.abs_diff(jx) + LEAF * (jy - iy)];
                // (Beyond one voxel diagonal for a mesh export: never `±∞`.)
                if m > margin {
                    bounds[j] = (d.signum() * m) as f32;
                }
            }
        }
    }
}
