//! Grading the lattice: where tetrahedra must be small.
//!
//! The size comes from the material heterogeneity (`sizing.rs`); geometry
//! adds refinement where stuffing would otherwise lose or distort the
//! surface. See [`HetRefine`] for the rules and their reasons.

use glam::DVec3;
use volcad_core::model::MAX_MATERIALS;
use volcad_core::{Aabb, Model};

use super::lattice::{Lattice, Refine};
use super::sizing::{SizeRule, heterogeneity};
use super::tets::EDGES;
use crate::job::ExportError;

/// Mean edge length of the Kuhn tetrahedron of a unit cube: edges 1, 1, 1,
/// √2, √2, √3, so `(3 + 2√2 + √3) / 6`.
pub const KUHN_MEAN_EDGE: f64 = 1.260_094_450_839_431_8;

/// Most root tetrahedra a lattice may start with.
const MAX_ROOTS: f64 = 5e7;

/// The root lattice for `rule`: cubes whose Kuhn tetrahedra have mean edge
/// `min_cell · 2^J ≥ max_cell`, so `3J` bisection levels reach `min_cell`.
pub fn lattice_for(model: &Model, rule: &SizeRule) -> Result<Lattice, ExportError> {
    let b = crate::design::bounded_box(model)?;
    let j = (rule.max_cell() / rule.min_cell())
        .log2()
        .ceil()
        .clamp(0.0, 20.0) as u32;
    let cube = rule.min_cell() * f64::from(1u32 << j) / KUHN_MEAN_EDGE;
    let n = (b.size() / cube).ceil().max(DVec3::ONE);
    // Integer vertex keys are i32: cubes × 2^(J+2) steps must fit.
    if n.max_element() * f64::from(1u32 << (j + 2)) >= f64::from(1u32 << 30) {
        return Err(ExportError::param(
            "--min-cell",
            format!(
                "max_cell / min_cell = {:.0} is too large for a design this size; raise --min-cell",
                rule.max_cell() / rule.min_cell()
            ),
        ));
    }
    if n.x * n.y * n.z * 6.0 > MAX_ROOTS {
        return Err(ExportError::param(
            "--max-cell",
            format!(
                "{:.0} root tetrahedra; use a larger --max-cell",
                n.x * n.y * n.z * 6.0
            ),
        ));
    }
    Ok(Lattice::new(b.min, b.max, cube, j))
}

/// Mean edge length of a tetrahedron.
pub fn mean_edge(c: &[DVec3; 4]) -> f64 {
    EDGES
        .iter()
        .map(|&(i, j)| (c[i] - c[j]).length())
        .sum::<f64>()
        / 6.0
}

/// The refinement rule: heterogeneity first, then geometry.
///
/// 1. **Size.** Split while the mean edge exceeds `L(h)` at any inside
///    sample (corners and centroid; `max_cell` when none is inside).
///    Tetrahedra wholly outside or wholly inside the surface (interval
///    bound) stop here; none is split below `min_cell`.
/// 2. **Lost features**, down to `min_cell`. Stuffing sees the surface only
///    through sign changes along lattice edges, so a wall, strut or hole
///    that slips between the vertices vanishes. Split when the centroid has
///    the other sign than all four corners, or an edge whose ends have the
///    same sign runs through the other side for more than `HIDDEN_RUN` of its
///    length (found by sphere tracing; only
///    tried when `|d(a)| + |d(b)| < |ab|`, since the distance is 1-Lipschitz
///    and otherwise the surface cannot reach the edge).
/// 3. **Boundary shape**, down to `L / SHAPE_FLOOR`. Where the surface
///    curves or has a crease, `d` is not linear along an edge that crosses
///    it, and the stuffed boundary (linear per element) cuts corners. Split
///    while `|d(mid) − (d(a) + d(b))/2| > SHAPE_TOL · |ab|` on such an edge.
///    This error is scale-invariant at a crease (it never goes away by
///    refining), hence the floor: sharp edges are rounded by at most about
///    `L/4`, and a pure region still meshes coarse.
pub struct HetRefine<'a> {
    /// The design.
    pub model: &'a Model,
    /// `h ↦ L`.
    pub rule: &'a SizeRule,
}

/// Fraction of an edge that a hidden crossing must span to refine.
pub const HIDDEN_RUN: f64 = 0.1;
/// Allowed non-linearity of `d` along a crossing edge (fraction of its length).
pub const SHAPE_TOL: f64 = 0.1;
/// Boundary-shape refinement stops at `L / SHAPE_FLOOR`.
pub const SHAPE_FLOOR: f64 = 4.0;

impl Refine for HetRefine<'_> {
    fn split(&self, c: &[DVec3; 4]) -> bool {
        let size = mean_edge(c);
        if size <= self.rule.min_cell() {
            return false;
        }
        let lo = c[0].min(c[1]).min(c[2]).min(c[3]);
        let hi = c[0].max(c[1]).max(c[2]).max(c[3]);
        let iv = self.model.interval(&Aabb::new(lo, hi));
        if iv.lo > 0.0 {
            return false;
        }
        let k = self.model.materials().len();
        let mut f = [0.0f64; MAX_MATERIALS];
        let centroid = (c[0] + c[1] + c[2] + c[3]) * 0.25;
        let mut l = f64::INFINITY;
        let mut d = [0.0f64; 5];
        for (di, p) in d.iter_mut().zip([c[0], c[1], c[2], c[3], centroid]) {
            *di = self.model.eval_into(p, &mut f[..k]);
            if *di <= 0.0 {
                l = l.min(self.rule.length(heterogeneity(&f[..k])));
            }
        }
        let l = if l.is_finite() {
            l
        } else {
            self.rule.max_cell()
        };
        if size > l {
            return true;
        }
        if iv.hi < 0.0 {
            return false;
        }
        // Lost features, down to min_cell.
        let inside = |v: f64| v <= 0.0;
        if d[..4].iter().all(|v| inside(*v) != inside(d[4])) {
            return true;
        }
        let hidden = EDGES.iter().any(|&(i, j)| {
            let (da, db) = (d[i], d[j]);
            let len = (c[i] - c[j]).length();
            inside(da) == inside(db)
                && da.abs() + db.abs() < len
                && self.hidden_run(c[i], c[j], da, db) > HIDDEN_RUN * len
        });
        if hidden {
            return true;
        }
        // Shape of the boundary (curvature, creases), down to l / floor.
        size > l / SHAPE_FLOOR
            && EDGES.iter().any(|&(i, j)| {
                let (da, db) = (d[i], d[j]);
                let len = (c[i] - c[j]).length();
                if inside(da) == inside(db) && da.abs() + db.abs() >= len {
                    return false;
                }
                let dm = self.model.distance((c[i] + c[j]) * 0.5);
                (dm - 0.5 * (da + db)).abs() > SHAPE_TOL * len
            })
    }
}

impl HetRefine<'_> {
    /// Length of the first run of the other sign along `a → b` (both ends
    /// have the same sign), found by sphere tracing with `|d|` (a step of
    /// `|d|` cannot jump over the surface when `d` is 1-Lipschitz); 0 when
    /// there is none or the ray only grazes the surface.
    fn hidden_run(&self, a: DVec3, b: DVec3, da: f64, db: f64) -> f64 {
        let len = (b - a).length();
        let dir = (b - a) / len;
        let out = da > 0.0;
        let mut t = da.abs();
        let mut steps = 0;
        loop {
            if t >= len - db.abs() || steps > 64 {
                return 0.0;
            }
            let v = self.model.distance(a + dir * t);
            steps += 1;
            if (v > 0.0) != out {
                break;
            }
            t += v.abs().max(1e-3 * len);
        }
        let t1 = t;
        while t < len && steps < 128 {
            let v = self.model.distance(a + dir * t);
            steps += 1;
            if (v > 0.0) == out {
                break;
            }
            t += v.abs().max(0.02 * len);
        }
        t.min(len) - t1
    }
}
