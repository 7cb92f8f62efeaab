//! Which segment each voxel belongs to, from its sampled fractions.
//!
//! A voxel is void when it is outside (`d > 0`), its fractions sum to
//! (almost) nothing, or it lies on the grid's outer layer (the grid is
//! padded so that layer is outside anyway; forcing it closes every mesh).
//! Fractions are normalised by their total `T = Σ f_i`. Then:
//!
//! * by the fraction `f = f_m / T` of one material `m`: segment
//!   `s = min(⌊f·n⌋, n − 1)`, i.e. ranges `[s/n, (s+1)/n)` with the top range
//!   closed. A material the design does not use has `f = 0` everywhere.
//! * by dominant material: the slot with the largest fraction (ties to the
//!   lowest), one segment per material of the design.
//!
//! Labels are `segment + 1` (0 = void), as [`super::contour`] takes them.

use std::sync::Arc;

use glam::DVec3;
use rayon::prelude::*;
use volcad_core::Model;
use volcad_core::interval::Interval;
use volcad_core::model::MAX_MATERIALS;
use volcad_core::sampler::{RectRows, Slab, fill_pattern};

use super::contour::Plane;
use super::interface::Interface;
use super::layer_dist::LayerDist;
use super::sign_row::sign_row;
use crate::dither::{BOUND_MARGIN as EPS, MIN_TOTAL};

/// How voxels are put into segments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Classifier {
    /// `n` ranges of the normalised fraction of slot `slot` (`None`: a
    /// material the design does not use, so `f = 0`).
    Ranges {
        /// The material's slot in the design, if it has one.
        slot: Option<usize>,
        /// Number of ranges.
        n: usize,
    },
    /// The dominant material among `k`.
    Dominant {
        /// Materials of the design.
        k: usize,
    },
}

/// Per-segment tallies.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tally {
    /// Voxels per segment.
    pub voxels: Vec<u64>,
    /// Sum per segment of the classifying fraction (the material's `f`, or
    /// the dominant fraction), for means. A solid tile the sampler proved
    /// uniform counts at its centre's value (the mean over the tile for
    /// gradings affine across it).
    pub sum_f: Vec<f64>,
}

impl Tally {
    /// Zero tallies for `n` segments.
    pub fn new(n: usize) -> Self {
        Self {
            voxels: vec![0; n],
            sum_f: vec![0.0; n],
        }
    }

    /// Add `other` (in a fixed order, so sums are deterministic).
    pub fn add(&mut self, other: &Tally) {
        self.add_row(&other.voxels, &other.sum_f);
    }

    /// Add one row's counts and sums.
    fn add_row(&mut self, voxels: &[u64], sum_f: &[f64]) {
        for (a, b) in self.voxels.iter_mut().zip(voxels) {
            *a += b;
        }
        for (a, b) in self.sum_f.iter_mut().zip(sum_f) {
            *a += b;
        }
    }
}

/// One row's [`Tally`], in the plane's buffers.
struct RowTally<'a> {
    voxels: &'a mut [u64],
    sum_f: &'a mut [f64],
}

impl Classifier {
    /// Number of segments.
    pub fn segments(&self) -> usize {
        match *self {
            Classifier::Ranges { n, .. } => n,
            Classifier::Dominant { k } => k,
        }
    }

    /// True when every fraction vector within `bounds` (one interval per
    /// material) gets the same non-void label, with a margin of 10⁻⁵ for the
    /// `f32` rounding of sampled fractions: the sampler may then fill a
    /// solid tile with one evaluation (see `Consumer::MeshContour`).
    pub fn uniform(&self, bounds: &[Interval]) -> bool {
        let sum_lo: f64 = bounds.iter().map(|i| i.lo).sum();
        let sum_hi: f64 = bounds.iter().map(|i| i.hi).sum();
        if !(sum_lo > f64::from(MIN_TOTAL) + EPS && sum_hi.is_finite()) {
            return false; // could be void
        }
        match *self {
            Classifier::Ranges { slot: None, .. } => true,
            Classifier::Ranges { slot: Some(s), n } => {
                let segment = |x: f64| ((x.clamp(0.0, 1.0) * n as f64).floor() as usize).min(n - 1);
                let lo = bounds[s].lo / sum_hi - EPS;
                let hi = bounds[s].hi / sum_lo + EPS;
                segment(lo) == segment(hi)
            }
            Classifier::Dominant { .. } => bounds.iter().enumerate().any(|(a, ba)| {
                bounds
                    .iter()
                    .enumerate()
                    .all(|(j, bj)| j == a || ba.lo > bj.hi + EPS)
            }),
        }
    }

    /// How [`super::contour`] cuts edges between segments. With one
    /// segment no edge joins two segments (edges to void are cut by the
    /// distance), so no interface values are stored: a one-material
    /// design's planes carry labels and distances only (values there would
    /// be written and copied for every voxel and read by no edge).
    pub fn interface(&self) -> Interface {
        match *self {
            _ if self.segments() == 1 => Interface::Midpoint,
            Classifier::Ranges { n, .. } => Interface::Ranges { n },
            Classifier::Dominant { k } => Interface::Dominant { k },
        }
    }

    /// Label (0 = void) and interface values of one inside voxel with
    /// fractions `f`; `value` gets [`Interface::stride`] numbers. Returns
    /// the label and the classifying fraction.
    #[inline]
    fn classify(&self, f: &[f32], value: &mut [f32]) -> (u16, f32) {
        let total: f32 = f.iter().sum();
        if total.is_nan() || total <= MIN_TOTAL {
            value.fill(0.0);
            return (0, 0.0);
        }
        let inv = 1.0 / total;
        match *self {
            // `value` is empty for one segment (see `interface`).
            Classifier::Ranges { slot, n } => {
                let x = slot.map_or(0.0, |s| (f[s] * inv).clamp(0.0, 1.0));
                if let Some(v) = value.first_mut() {
                    *v = x;
                }
                let s = ((x * n as f32) as usize).min(n - 1);
                (s as u16 + 1, x)
            }
            Classifier::Dominant { .. } => {
                let mut best = 0;
                for (i, fi) in f.iter().enumerate() {
                    if *fi > f[best] {
                        best = i;
                    }
                }
                for (v, fi) in value.iter_mut().zip(f) {
                    *v = fi * inv;
                }
                (best as u16 + 1, f[best] * inv)
            }
        }
    }

    /// Distance and interface values (into `value`, zero when void) of the
    /// sample at `p` of `model`: evaluated as the sampler evaluates a voxel
    /// it does not skip, and classified as [`Self::plane_into`] classifies
    /// it. The flat regions' fallback takes its samples again through this
    /// (see `super::flat::SampleAt`).
    pub fn sample(&self, model: &Model, p: DVec3, value: &mut [f32]) -> f32 {
        value.fill(0.0);
        let k = model.materials().len();
        if k == 0 {
            return model.distance(p) as f32;
        }
        let mut f = [0.0; MAX_MATERIALS];
        let d = model.eval_into(p, &mut f[..k]) as f32;
        if d <= 0.0 {
            let f: [f32; MAX_MATERIALS] = std::array::from_fn(|i| f[i] as f32);
            self.classify(&f[..k], value);
        }
        d
    }

    /// Labels, values and tallies of the voxels `xs` of one row, one by one
    /// (`dist` and `fracs` of the row, `k` fractions a voxel).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn voxels(
        &self,
        dist: &[f32],
        fracs: &[f32],
        k: usize,
        xs: std::ops::Range<usize>,
        labels: &mut [u16],
        values: &mut [f32],
        t: &mut RowTally,
    ) {
        let stride = values.len() / labels.len();
        // The last inside voxel classified in this run: solid regions with
        // constant fractions repeat it voxel after voxel, and comparing k
        // bit patterns is cheaper than normalising (the result is the same
        // bit for bit).
        let mut last: Option<(usize, u16, f32)> = None;
        let mut x = xs.start;
        while x < xs.end {
            // Outside voxels (labels stay 0) are most of what is left
            // between solid runs: skipped eight at a time, with one
            // vector comparison and no branch per voxel.
            if x + 8 <= xs.end && dist[x..x + 8].iter().fold(true, |all, d| all & (*d > 0.0)) {
                x += 8;
                continue;
            }
            let v = x;
            x += 1;
            if dist[v] > 0.0 {
                continue;
            }
            let fv = &fracs[v * k..(v + 1) * k];
            let (lab, f) = match last {
                Some((u, lab, f)) if same_bits(&fracs[u * k..][..k], fv) => {
                    copy_value(values, u, v, stride);
                    (lab, f)
                }
                _ => self.classify(fv, &mut values[v * stride..(v + 1) * stride]),
            };
            last = Some((v, lab, f));
            labels[v] = lab;
            if lab > 0 {
                t.voxels[lab as usize - 1] += 1;
                t.sum_f[lab as usize - 1] += f64::from(f);
            }
        }
    }

    /// The plane of labels for layer `l` of `slab` (grid `[nx, ny, nz]`,
    /// global layer `z`), with its tallies; for tests, which compare
    /// samplers (it copies the slab's distances; exports share them
    /// through [`Self::plane_into`]).
    #[cfg(test)]
    pub fn plane(&self, slab: &Slab, l: usize, dims: [usize; 3], z: usize) -> (Plane, Tally) {
        let dist = Arc::new(slab.dist.clone());
        self.plane_into(slab, &dist, l, dims, z, Plane::default())
    }

    /// `Self::plane` into the buffers of a plane the caller no longer
    /// needs (fresh buffers each layer cost page faults and zeroing by the
    /// kernel: a tenth of a cube export), with the slab's distances
    /// `slab_dist` shared rather than copied (`slab.dist` is not read).
    pub fn plane_into(
        &self,
        slab: &Slab,
        slab_dist: &Arc<Vec<f32>>,
        l: usize,
        [nx, ny, nz]: [usize; 3],
        z: usize,
        reuse: Plane,
    ) -> (Plane, Tally) {
        let layer = nx * ny;
        let k = slab.k;
        let stride = self.interface().stride();
        let Plane {
            mut label,
            dist,
            mut value,
            ..
        } = reuse.for_layer(slab_dist, l, layer);
        let rows_dist: &[f32] = &dist;
        let fracs = &slab.fracs[l * layer * k..(l + 1) * layer * k];
        label.clear();
        label.resize(layer, 0);
        value.clear();
        value.resize(layer * stride, 0.0);
        let segments = self.segments();
        let edge_plane = z == 0 || z + 1 == nz;
        let runs = self.solid_runs(slab, z, nx, ny);
        // Each row's values (none with one segment: empty rows, since
        // chunks of zero values do not exist).
        let value_rows: Vec<&mut [f32]> = if stride == 0 {
            (0..ny).map(|_| &mut [][..]).collect()
        } else {
            value.chunks_mut(nx * stride).collect()
        };
        // Each row's tallies, in one buffer per plane (not two small
        // vectors a row, allocated and freed per row), added up in row order.
        let per_row = segments.max(1);
        let mut counts = vec![0u64; ny * per_row];
        let mut sums = vec![0.0f64; ny * per_row];
        label
            .par_chunks_mut(nx)
            .zip(value_rows)
            .zip(counts.par_chunks_mut(per_row))
            .zip(sums.par_chunks_mut(per_row))
            .enumerate()
            .for_each(|(y, (((labels, values), voxels), sum_f))| {
                let mut t = RowTally { voxels, sum_f };
                if edge_plane || y == 0 || y + 1 == ny {
                    return;
                }
                let row = &rows_dist[y * nx..(y + 1) * nx];
                let fracs = &fracs[y * nx * k..(y + 1) * nx * k];
                let mut x = 1;
                for sp in runs.rows.row(y) {
                    let (a, b) = (sp.x0.max(x), sp.x1.min(nx - 1));
                    if a >= b {
                        continue;
                    }
                    // (Most runs start where the last ended: the cube's
                    // layers have about fourteen runs a row, and the empty
                    // calls were a sixth of labelling it.)
                    if x < a {
                        self.voxels(row, fracs, k, x..a, labels, values, &mut t);
                    }
                    // The run's voxels are inside and share its rectangle's
                    // fractions, classified once.
                    let (lab, fv) = runs.classes[sp.rect];
                    let v = &runs.values[sp.rect * stride..(sp.rect + 1) * stride];
                    labels[a..b].fill(lab);
                    // (Guarded here too: without values the call into
                    // volcad-core per run would copy nothing.)
                    if stride > 0 {
                        fill_pattern(&mut values[a * stride..b * stride], v);
                    }
                    if lab > 0 {
                        let n = (b - a) as u64;
                        t.voxels[lab as usize - 1] += n;
                        t.sum_f[lab as usize - 1] += f64::from(fv) * n as f64;
                    }
                    x = b;
                }
                self.voxels(row, fracs, k, x..nx - 1, labels, values, &mut t);
            });
        let mut tally = Tally::new(segments);
        for (c, f) in counts.chunks(per_row).zip(sums.chunks(per_row)) {
            tally.add_row(c, f);
        }
        let bits = Vec::new();
        (
            Plane {
                label,
                dist,
                value,
                bits,
            },
            tally,
        )
    }
}

/// The label and classifying fraction of every inside voxel of a design
/// whose fractions are fixed (one material, or a grade of constants),
/// when its planes carry no interface values (one segment): every such
/// voxel's sampled fractions are the design's mix, bit for bit, so
/// [`fixed_plane_into`] labels a plane from the distances' signs alone.
pub fn fixed_class(classifier: &Classifier, model: &Model) -> Option<(u16, f32)> {
    let k = model.materials().len();
    if classifier.interface().stride() != 0 || k == 0 {
        return None;
    }
    let mut f = [0.0f64; MAX_MATERIALS];
    if !model.fixed_fractions(&mut f[..k]) {
        return None;
    }
    // As the sampler stores them (`f32`).
    let one: [f32; MAX_MATERIALS] = std::array::from_fn(|i| f[i] as f32);
    Some(classifier.classify(&one[..k], &mut []))
}

/// [`Classifier::plane_into`] for a design of [`fixed_class`] `(lab, fv)`:
/// `lab` where the distance is not above zero, void elsewhere and on the
/// grid's outer layer, with the same tallies, and the labels as bits too
/// ([`Plane::bits`]); no fractions are read, and no zeroing pass precedes
/// the labels (each is written once).
pub fn fixed_plane_into(
    slab_dist: &Arc<Vec<f32>>,
    l: usize,
    [nx, ny, nz]: [usize; 3],
    z: usize,
    reuse: Plane,
    (lab, fv): (u16, f32),
) -> (Plane, Tally) {
    let layer = nx * ny;
    let words = nx.div_ceil(64);
    let Plane {
        mut label,
        dist,
        mut value,
        mut bits,
    } = reuse.for_layer(slab_dist, l, layer);
    let rows_dist: &[f32] = &dist;
    // Every label and word is written below: a reused plane keeps its length.
    label.resize(layer, 0);
    bits.resize(words * ny, 0);
    value.clear();
    // (One segment: `lab` is 1, or 0 when the mix is void.)
    debug_assert!(lab <= 1, "one segment's label {lab}");
    let void = z == 0 || z + 1 == nz || nx < 3 || lab == 0;
    let counts: Vec<u64> = label
        .par_chunks_mut(nx)
        .zip(bits.par_chunks_mut(words))
        .enumerate()
        .map(|(y, (labels, bits))| {
            if void || y == 0 || y + 1 == ny {
                labels.fill(0);
                bits.fill(0);
                return 0;
            }
            sign_row(labels, bits, &rows_dist[y * nx..(y + 1) * nx], lab);
            // The grid's outer columns are void.
            labels[0] = 0;
            labels[nx - 1] = 0;
            bits[0] &= !1;
            bits[(nx - 1) / 64] &= !(1 << ((nx - 1) % 64));
            bits.iter().map(|w| u64::from(w.count_ones())).sum()
        })
        .collect();
    let mut tally = Tally::new(1);
    if lab > 0 {
        for n in counts {
            tally.add_row(&[n], &[f64::from(fv) * n as f64]);
        }
    }
    let plane = Plane {
        label,
        dist,
        value,
        bits,
    };
    (plane, tally)
}

impl Plane {
    /// This retired plane's buffers, for layer `l` (of `layer` voxels) of
    /// the shared slab distances `slab_dist`, with that layer's view.
    fn for_layer(self, slab_dist: &Arc<Vec<f32>>, l: usize, layer: usize) -> Plane {
        let dist = LayerDist::new(slab_dist, l * layer..(l + 1) * layer);
        Plane { dist, ..self }
    }
}

/// One layer's solid rectangles as runs, row by row, and each
/// rectangle's classification (label, classifying fraction, values).
struct SolidRuns {
    rows: RectRows,
    classes: Vec<(u16, f32)>,
    values: Vec<f32>,
}

impl Classifier {
    /// [`SolidRuns`] of layer `z` of `slab` (`nx × ny`).
    fn solid_runs(&self, slab: &Slab, z: usize, nx: usize, ny: usize) -> SolidRuns {
        let (k, stride) = (slab.k, self.interface().stride());
        let rows = slab.rect_rows(z, nx, ny);
        let rects = &slab.rects[rows.rects.clone()];
        let mut values = vec![0.0; rects.len() * stride];
        let classes = (rects.iter().enumerate())
            .map(|(i, r)| {
                let f = &slab.rect_fracs[r.at..r.at + k];
                self.classify(f, &mut values[i * stride..(i + 1) * stride])
            })
            .collect();
        SolidRuns {
            rows,
            classes,
            values,
        }
    }
}

/// Copies sample `from`'s `stride` values onto sample `to`'s (`from <
/// to`), as fixed-size moves for the usual strides. Nothing for a plane
/// without values (one segment): called once a voxel, and `fill_pattern`
/// is a call into `volcad-core` that would copy nothing.
#[inline]
fn copy_value(values: &mut [f32], from: usize, to: usize, stride: usize) {
    if stride == 0 {
        return;
    }
    let (done, rest) = values.split_at_mut(to * stride);
    fill_pattern(
        &mut rest[..stride],
        &done[from * stride..(from + 1) * stride],
    );
}

/// Equal bit patterns (unlike `==`, tells `-0.0` from `0.0`).
#[inline]
fn same_bits(a: &[f32], b: &[f32]) -> bool {
    a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_close_the_top_and_normalise() {
        let c = Classifier::Ranges {
            slot: Some(0),
            n: 4,
        };
        let mut v = [0.0];
        assert_eq!(c.classify(&[1.0, 0.0], &mut v).0, 4);
        assert_eq!(c.classify(&[0.25, 0.75], &mut v).0, 2);
        assert_eq!(c.classify(&[0.1, 0.3], &mut v), (2, 0.25));
        assert_eq!(c.classify(&[0.0, 0.0], &mut v).0, 0);
        let unused = Classifier::Ranges { slot: None, n: 3 };
        assert_eq!(unused.classify(&[0.5, 0.5], &mut v).0, 1);
    }

    #[test]
    fn copied_values_land_on_their_sample() {
        for stride in 0..6 {
            let v: Vec<f32> = (0..stride).map(|i| i as f32 + 0.5).collect();
            let mut w = vec![-1.0; 4 * stride];
            w[stride..2 * stride].copy_from_slice(&v);
            copy_value(&mut w, 1, 3, stride);
            assert_eq!(w[3 * stride..], v[..], "{stride}");
            assert!(w[2 * stride..3 * stride].iter().all(|&x| x == -1.0));
        }
    }

    #[test]
    fn one_segment_stores_no_values_and_classifies_the_same() {
        let one = Classifier::Dominant { k: 1 };
        assert_eq!(one.interface(), Interface::Midpoint);
        assert_eq!(one.classify(&[0.5], &mut []), (1, 1.0));
        assert_eq!(one.classify(&[0.0], &mut []), (0, 0.0));
        let range = Classifier::Ranges {
            slot: Some(1),
            n: 1,
        };
        assert_eq!(range.interface().stride(), 0);
        assert_eq!(range.classify(&[0.1, 0.3], &mut []), (1, 0.75));
        // Two segments keep their values, and the classifying fraction is
        // the stored one bit for bit.
        let two = Classifier::Dominant { k: 2 };
        let mut v = [0.0; 2];
        let (label, f) = two.classify(&[0.3, 0.6], &mut v);
        assert_eq!((label, f.to_bits()), (2, v[1].to_bits()));
    }

    #[test]
    fn dominant_picks_the_largest_lowest_on_ties() {
        let c = Classifier::Dominant { k: 3 };
        let mut v = [0.0; 3];
        assert_eq!(c.classify(&[0.2, 0.5, 0.3], &mut v).0, 2);
        assert_eq!(c.classify(&[0.4, 0.2, 0.4], &mut v).0, 1);
        assert_eq!(v, [0.4, 0.2, 0.4]);
    }
}
