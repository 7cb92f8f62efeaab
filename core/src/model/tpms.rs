//! Sheet triply periodic minimal surfaces with a wall thickness.
//!
//! For a level-set function f with period `cell` (X = 2π x / cell_x, ...):
//! gyroid `sin X cos Y + sin Y cos Z + sin Z cos X`, Schwarz P
//! `cos X + cos Y + cos Z`, diamond
//! `sin X sin Y sin Z + sin X cos Y cos Z + cos X sin Y cos Z + cos X cos Y sin Z`.
//! The distance to the surface f = 0 is `|f| / |∇f|` to first order, so the
//! wall of thickness t is `{ |f| ≤ (t/2)·|∇f| }` (its thickness is what the
//! user asked for). The field we return has exactly that zero set:
//! `φ = (|f| − (t/2)·|∇f|) / G`, where G bounds |∇f| globally. Dividing by
//! the global bound keeps φ from overestimating the distance (a first-order
//! `|f|/|∇f|` overshoots near saddle points, which shows as speckles when
//! sphere tracing). Intervals use that f is G-Lipschitz:
//! `(|f(c)| − G·r)/G − t/2 ≤ φ ≤ (|f(c)| + G·r)/G` over a ball of radius r.

use glam::DVec3;

use crate::bounds::Aabb;
use crate::fastmath::sin_cos;
use crate::interval::Interval;
use crate::node::TpmsType;

/// A prepared TPMS sheet.
#[derive(Clone, Copy, Debug)]
pub struct Tpms {
    kind: TpmsType,
    /// 2π / cell, per axis.
    k: DVec3,
    half_t: f64,
    /// Global bound of |∇f| in 1/mm.
    g: f64,
}

impl Tpms {
    /// A sheet of `kind` with period `cell` (mm) and wall `thickness` (mm).
    pub fn new(kind: TpmsType, cell: DVec3, thickness: f64) -> Self {
        let k = DVec3::splat(std::f64::consts::TAU) / cell;
        let kmax = k.max_element();
        let g = match kind {
            TpmsType::Gyroid => kmax * 6f64.sqrt(),
            TpmsType::SchwarzP => kmax * 3f64.sqrt(),
            TpmsType::Diamond => kmax * 2.0 * 3f64.sqrt(),
        };
        Self {
            kind,
            k,
            half_t: thickness * 0.5,
            g,
        }
    }

    /// f and ∇f at `p`.
    #[inline]
    fn field(&self, p: DVec3) -> (f64, DVec3) {
        let q = p * self.k;
        let (sx, cx) = sin_cos(q.x);
        let [sy, cy, sz, cz] = row::sin_cos_yz(q.y, q.z);
        match self.kind {
            TpmsType::Gyroid => (
                sx * cy + sy * cz + sz * cx,
                DVec3::new(cx * cy - sz * sx, cy * cz - sx * sy, cz * cx - sy * sz) * self.k,
            ),
            TpmsType::SchwarzP => (cx + cy + cz, DVec3::new(-sx, -sy, -sz) * self.k),
            TpmsType::Diamond => (
                sx * sy * sz + sx * cy * cz + cx * sy * cz + cx * cy * sz,
                DVec3::new(
                    cx * sy * sz + cx * cy * cz - sx * sy * cz - sx * cy * sz,
                    sx * cy * sz - sx * sy * cz + cx * cy * cz - cx * sy * sz,
                    sx * sy * cz - sx * cy * sz - cx * sy * sz + cx * cy * cz,
                ) * self.k,
            ),
        }
    }

    /// A distance bound to the sheet (see the module doc).
    #[inline]
    pub fn dist(&self, p: DVec3) -> f64 {
        let (f, grad) = self.field(p);
        (f.abs() - self.half_t * grad.length()) / self.g
    }

    /// A conservative interval over `b`.
    pub fn interval(&self, b: &Aabb) -> Interval {
        let (f, _) = self.field(b.center());
        let r = b.half_diagonal();
        let lo = (f.abs() - self.g * r).max(0.0) / self.g - self.half_t;
        let hi = (f.abs() + self.g * r) / self.g;
        Interval::new(lo, hi)
    }
}

/// Samplers walk rows of voxels along x, where y and z stay the same: the
/// last `(y, z)` pair's sines and cosines are kept per thread and reused
/// when the same bits come again. They are a pure function of those bits,
/// so the values are exactly the ones a fresh computation gives.
mod row {
    use std::cell::Cell;

    use crate::fastmath::sin_cos;

    thread_local! {
        static LAST: Cell<(u64, u64, [f64; 4])> = const { Cell::new((u64::MAX, u64::MAX, [f64::NAN; 4])) };
    }

    /// `[sin y, cos y, sin z, cos z]`.
    #[inline]
    pub fn sin_cos_yz(y: f64, z: f64) -> [f64; 4] {
        LAST.with(|c| {
            let (ky, kz, v) = c.get();
            if ky == y.to_bits() && kz == z.to_bits() {
                return v;
            }
            let ((sy, cy), (sz, cz)) = (sin_cos(y), sin_cos(z));
            let v = [sy, cy, sz, cz];
            c.set((y.to_bits(), z.to_bits(), v));
            v
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interval_contains_samples() {
        for kind in [TpmsType::Gyroid, TpmsType::SchwarzP, TpmsType::Diamond] {
            let t = Tpms::new(kind, DVec3::new(5.0, 6.0, 7.0), 0.4);
            for i in 0..50 {
                let c = DVec3::new(
                    i as f64 * 0.37,
                    i as f64 * 0.91 - 3.0,
                    (i * i) as f64 * 0.05,
                );
                let b = Aabb::from_center_size(c, DVec3::splat(0.5 + (i % 5) as f64 * 0.3));
                let iv = t.interval(&b);
                for j in 0..27 {
                    let f = DVec3::new((j % 3) as f64, ((j / 3) % 3) as f64, (j / 9) as f64) * 0.5;
                    let p = b.min + b.size() * f;
                    let d = t.dist(p);
                    assert!(iv.lo <= d + 1e-12 && d <= iv.hi, "{kind:?} {iv:?} {d}");
                }
            }
        }
    }

    #[test]
    fn row_cache_gives_the_fresh_values() {
        let a = Tpms::new(TpmsType::Gyroid, DVec3::new(5.0, 6.0, 7.0), 0.4);
        let b = Tpms::new(TpmsType::Diamond, DVec3::splat(3.0), 0.2);
        // Rows along x (cache hits), alternating nodes and rows (misses).
        let pts: Vec<DVec3> = (0..400)
            .map(|i| DVec3::new(i as f64 * 0.07, (i / 50) as f64 * 0.3, -((i / 30) as f64)))
            .collect();
        let fresh = |t: &Tpms, p: DVec3| {
            let q = p * t.k;
            let ((sx, cx), (sy, cy), (sz, cz)) = (sin_cos(q.x), sin_cos(q.y), sin_cos(q.z));
            match t.kind {
                TpmsType::Gyroid => sx * cy + sy * cz + sz * cx,
                _ => sx * sy * sz + sx * cy * cz + cx * sy * cz + cx * cy * sz,
            }
        };
        for (i, p) in pts.iter().enumerate() {
            // Mostly one node along a row (hits), now and then the other
            // node in between (a miss, then a miss back).
            let nodes: &[&Tpms] = if i % 7 == 0 { &[&a, &b, &a] } else { &[&a] };
            for t in nodes {
                assert_eq!(t.field(*p).0.to_bits(), fresh(t, *p).to_bits(), "{p}");
            }
        }
    }

    #[test]
    fn gyroid_wall_is_about_the_thickness() {
        // Along the surface normal at the origin (f(0) = 0, ∇f ∥ (1,1,1))
        // the inside run is about t long.
        let t = Tpms::new(TpmsType::Gyroid, DVec3::splat(10.0), 0.5);
        let step = 0.001;
        let mut inside = 0;
        for i in -1000..1000 {
            let p = DVec3::ONE.normalize() * (i as f64 * step);
            if t.dist(p) <= 0.0 {
                inside += 1;
            }
        }
        let run = inside as f64 * step;
        assert!((run - 0.5).abs() < 0.02, "{run}");
    }
}
