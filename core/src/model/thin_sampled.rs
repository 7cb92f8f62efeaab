//! The thinnest feature of geometry whose thickness the tree does not state
//! (a mesh, a `Function`, a simulation field, text, a cone), estimated by
//! sampling the design's signed distance.
//!
//! A wall's thickness is twice the radius of the largest ball inside it,
//! whose centre lies on the medial surface, where the depth `-d` has a
//! ridge. The estimate:
//!
//! 1. samples `d` on a grid of spacing `h` over the design's box, `h` the
//!    smallest that keeps the grid within [`SAMPLE_BUDGET`] samples;
//! 2. keeps the ridge points: inside samples with no deeper sample among
//!    their 26 neighbours and at least one inside neighbour (a lone inside
//!    sample is a speck or the tip of a sharp edge, not a wall or strut);
//! 3. through the [`CANDIDATES`] shallowest ridge points, measures chords
//!    of the solid (from exit to exit, each exit refined by bisection)
//!    along the distance's gradient and 13 fixed directions; the shortest
//!    chord through a medial point is the wall's thickness (along the
//!    normal), any other chord is longer, so the minimum never understates
//!    it by more than the bisection's tolerance;
//! 4. reports the shortest chord through a ridge point at least `h` from
//!    the surface (its nearest exit). The last inside sample before a cut
//!    (a sheet clipped by a box, meeting it at a shallow angle) is a ridge
//!    of the grid at any depth under `h`, where the sheet thins to a sharp
//!    edge; deeper ridge points lie on walls and struts. A wall thicker
//!    than `3 h` always has a sample within `h / 2` of its middle, so it is
//!    measured; a thinner one only when a sample falls near its middle,
//!    and nothing thinner than `2 h` is reported: the note says so.
//!
//! Gaps between parts are measured the same way on the outside: the
//! middle of a gap is where the outside distance has a crease with
//! opposite slopes (its gradient on the grid nearly vanishes); the chord
//! through empty space from one surface to the other, along a direction
//! that meets both surfaces square (within 25°), is the gap's width. A
//! concave corner's crease has a gradient of at least `cos 45°` and meets
//! its walls at 45°, so it is never taken for a gap. Only the outside
//! within [`GAP_BAND`] spacings of the surface is sampled exactly: gaps up
//! to twice that are measured.
//!
//! Chords step by the distance where it is a bound (1-Lipschitz) and by
//! `h / 4` elsewhere, so a math-string field is crossed, not jumped over.
//! Every stage collects in index order and ties break by index: the result
//! is the same on any number of threads.

use glam::DVec3;
use rayon::prelude::*;

use super::Model;
use crate::aabb::Aabb;

/// Most samples of the distance on the grid (the chords add at most a few
/// hundred thousand more).
pub const SAMPLE_BUDGET: usize = 1 << 21;

/// Ridge points whose chords are measured, shallowest first.
pub const CANDIDATES: usize = 2048;

/// Most steps of one half-chord; past them the chord counts as thick.
const MAX_STEPS: usize = 256;

/// Spacings outside the surface that are sampled exactly for gaps: a
/// block of samples whose distance is certainly larger is filled with its
/// lower bound (it holds no gap narrower than twice this).
pub const GAP_BAND: f64 = 4.0;

/// Largest grid gradient of the outside distance at a gap's middle: a
/// sample within `h / 2` of the middle plane has a central difference of
/// at most `1/2` across it, and one on a concave corner's crease at least
/// `cos 45°`. For a distance that is not a bound the same test is made
/// relative to the one-sided differences, whose scale is the field's.
const GAP_GRADIENT: f64 = 0.6;

/// Least `|cos|` between a gap's chord and the surface normal at each of
/// its ends (25°): the two sides of a gap face each other; a concave
/// corner's walls meet a chord through its crease at 45°.
const SQUARE: f64 = 0.9;

/// Bisection steps refining each exit: to within `h / 4 / 2^12`, far
/// below `h` (an exit is crossed by a step of at most `h / 4`).
const BISECT: usize = 12;

/// The thinnest feature sampling found.
#[derive(Clone, Debug, PartialEq)]
pub struct SampledFeature {
    /// Its thickness in mm: the shortest chord through a ridge point.
    pub thickness: f64,
    /// The ridge point the chord passes through, in mm.
    pub at: DVec3,
}

/// What sampling the design found.
#[derive(Clone, Debug, PartialEq)]
pub struct Sampled {
    /// The grid spacing `h` in mm: features thinner than `2 h` are not
    /// reported, and those thinner than `3 h` only where a sample falls
    /// near their middle.
    pub spacing: f64,
    /// The thinnest feature of at least `2 spacing`, if the design has
    /// one at this spacing.
    pub feature: Option<SampledFeature>,
    /// The narrowest gap between surfaces (empty space between two parts,
    /// or a slot) of at least `2 spacing`, if sampling found one.
    pub gap: Option<SampledFeature>,
}

/// A kept estimate: the depth it was sampled to, and what it found.
pub(super) type SampledMemo = (f64, Option<Sampled>);

/// Which side of the surface a chord crosses: the solid (walls and
/// struts) or the empty space around it (gaps).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    Inside,
    Outside,
}

impl Side {
    /// True once a chord from this side has crossed the surface.
    fn crossed(self, v: f64) -> bool {
        match self {
            Side::Inside => v > 0.0,
            Side::Outside => v <= 0.0,
        }
    }
}

/// The sampling grid: `dims` samples from `origin`, `h` apart.
struct Grid {
    origin: DVec3,
    h: f64,
    dims: [usize; 3],
}

impl Grid {
    /// The grid over `b` within the budget, one sample beyond each side;
    /// `None` for an empty or unbounded box.
    fn over(b: &Aabb) -> Option<Grid> {
        if b.is_empty() || !b.is_finite() {
            return None;
        }
        let s = b.size();
        let longest = s.max_element();
        if !(longest > 0.0 && longest.is_finite()) {
            return None;
        }
        // A flat box has no volume to spread the budget over: at most 1024
        // samples along its longest side.
        let mut h = (s.x * s.y * s.z / SAMPLE_BUDGET as f64)
            .cbrt()
            .max(longest / 1024.0);
        loop {
            let dims = s.to_array().map(|v| (v / h).ceil() as usize + 3);
            if dims.iter().map(|&n| n as f64).product::<f64>() <= SAMPLE_BUDGET as f64 {
                return Some(Grid {
                    origin: b.min - DVec3::splat(h),
                    h,
                    dims,
                });
            }
            h *= 1.05;
        }
    }

    fn at(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.origin + DVec3::new(i as f64, j as f64, k as f64) * self.h
    }

    fn point(&self, idx: usize) -> DVec3 {
        let [nx, ny, _] = self.dims;
        self.at(idx % nx, (idx / nx) % ny, idx / (nx * ny))
    }
}

impl Model {
    /// The spacing `h` (mm) that [`Model::sampled_thinnest`] samples at,
    /// without sampling; `None` when the design's box is unbounded. Every
    /// feature it reports is at least `2 h` thick, so cells of `h` or less
    /// resolve whatever it could find.
    pub fn thin_sampling_spacing(&self) -> Option<f64> {
        Grid::over(&self.bbox).map(|g| g.h)
    }

    /// The design's thinnest feature estimated by sampling (see the module
    /// doc); `None` when the design's box is unbounded. Computed once per
    /// model and kept.
    pub fn sampled_thinnest(&self) -> Option<Sampled> {
        self.sampled_thinnest_below(f64::INFINITY)
    }

    /// [`Self::sampled_thinnest`] where only features thinner than `widest`
    /// mm need be found (an export warns of those under two cells): where
    /// the distance is a bound, a chord through a sample at depth `δ` is at
    /// least `2δ` long, so samples deeper than `widest / 2` are bounded, not
    /// evaluated (the inside of a large solid, most of a coarse export's
    /// sampling). A thicker feature may then go unreported. Kept per model
    /// with the widest it was made for; a wider request makes it again.
    pub fn sampled_thinnest_below(&self, widest: f64) -> Option<Sampled> {
        let bound = self.distance_is_bound();
        let deepest = if bound { widest / 2.0 } else { f64::INFINITY };
        let mut memo = self
            .sampled
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some((made_for, s)) = &*memo
            && *made_for >= deepest
        {
            return s.clone();
        }
        let made = Grid::over(&self.bbox).map(|g| {
            let d = sample(self, &g, deepest);
            let ridges = ridge_points(&g, &d, deepest);
            let feature = shortest(self, &g, &ridges, bound, Side::Inside);
            let gap = shortest(self, &g, &gap_points(&g, &d, bound), bound, Side::Outside);
            Sampled {
                spacing: g.h,
                feature,
                gap,
            }
        });
        *memo = Some((deepest, made.clone()));
        made
    }
}

/// The shortest chord on `side` through the candidates at least `h` from
/// the surface (their nearest exit), ties broken by index.
fn shortest(
    model: &Model,
    g: &Grid,
    candidates: &[(f64, usize)],
    bound: bool,
    side: Side,
) -> Option<SampledFeature> {
    candidates
        .par_iter()
        .filter_map(|&(_, idx)| {
            let (chord, near) = thinnest_chord(model, g.point(idx), g.h, bound, side);
            (near >= g.h && chord.is_finite()).then_some((chord, idx))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
        .map(|(thickness, idx)| SampledFeature {
            thickness,
            at: g.point(idx),
        })
}

/// Samples per side of the blocks that [`sample`] bounds before sampling.
const BLOCK: usize = 8;

/// The distance at every grid point, x fastest. A block of samples (or an
/// octant of a block that is not) whose distance interval lies wholly
/// beyond [`GAP_BAND`] spacings outside is filled with the interval's
/// lower end instead: ridge points are inside
/// samples compared with their neighbours, and any positive value outside
/// compares the same; gap points lie within the band. Likewise a block
/// deeper inside than `deepest` is filled with its interval's upper end:
/// ridge points are kept only above that depth, and a filled sample is
/// never shallower than `−deepest`, so it compares with a shallower
/// neighbour as its true (deeper) value would.
fn sample(model: &Model, g: &Grid, deepest: f64) -> Vec<f64> {
    let [nx, ny, nz] = g.dims;
    let [bx, by, bz] = g.dims.map(|n| n.div_ceil(BLOCK));
    let band = GAP_BAND * g.h;
    // The value a box of samples takes without evaluation, if any.
    let settled = |b: &Aabb| {
        let iv = model.interval(b);
        if iv.lo > band {
            Some(iv.lo)
        } else if iv.hi < -deepest {
            Some(iv.hi)
        } else {
            None
        }
    };
    let blocks: Vec<Vec<f64>> = (0..bx * by * bz)
        .into_par_iter()
        .map(|b| {
            let (i0, j0, k0) = (b % bx * BLOCK, b / bx % by * BLOCK, b / (bx * by) * BLOCK);
            let (i1, j1, k1) = (
                (i0 + BLOCK).min(nx),
                (j0 + BLOCK).min(ny),
                (k0 + BLOCK).min(nz),
            );
            let whole = settled(&Aabb::new(g.at(i0, j0, k0), g.at(i1 - 1, j1 - 1, k1 - 1)));
            // A block near the surface is bounded again by its eight
            // octants, whose tighter intervals settle more of it.
            let mut octants = [whole; 8];
            if whole.is_none() {
                let half = BLOCK / 2;
                for (o, v) in octants.iter_mut().enumerate() {
                    let (a0, b0, c0) =
                        (i0 + o % 2 * half, j0 + o / 2 % 2 * half, k0 + o / 4 * half);
                    if a0 < i1 && b0 < j1 && c0 < k1 {
                        let (a1, b1, c1) = (
                            (a0 + half).min(i1),
                            (b0 + half).min(j1),
                            (c0 + half).min(k1),
                        );
                        *v = settled(&Aabb::new(g.at(a0, b0, c0), g.at(a1 - 1, b1 - 1, c1 - 1)));
                    }
                }
            }
            let at = |(i, j, k): (usize, usize, usize)| {
                let half = BLOCK / 2;
                let o = (i - i0) / half + 2 * ((j - j0) / half) + 4 * ((k - k0) / half);
                octants[o].unwrap_or_else(|| model.distance(g.at(i, j, k)))
            };
            (k0..k1)
                .flat_map(|k| (j0..j1).flat_map(move |j| (i0..i1).map(move |i| (i, j, k))))
                .map(at)
                .collect()
        })
        .collect();
    let mut d = vec![0.0; nx * ny * nz];
    for (b, vals) in blocks.iter().enumerate() {
        let (i0, j0, k0) = (b % bx * BLOCK, b / bx % by * BLOCK, b / (bx * by) * BLOCK);
        let w = (i0 + BLOCK).min(nx) - i0;
        let h = (j0 + BLOCK).min(ny) - j0;
        for (r, row) in vals.chunks(w).enumerate() {
            let (j, k) = (j0 + r % h, k0 + r / h);
            let start = i0 + nx * (j + ny * k);
            d[start..start + w].copy_from_slice(row);
        }
    }
    d
}

/// The [`CANDIDATES`] shallowest of `found` (depth, index), ordered by
/// depth then index.
fn shallowest(mut found: Vec<(f64, usize)>) -> Vec<(f64, usize)> {
    found.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    found.truncate(CANDIDATES);
    found
}

/// `test(idx)` at every sample off the grid's border, in index order.
fn scan<F>(g: &Grid, test: F) -> Vec<(f64, usize)>
where
    F: Fn(usize) -> Option<(f64, usize)> + Sync,
{
    let [nx, ny, nz] = g.dims;
    (1..nz.saturating_sub(1))
        .into_par_iter()
        .flat_map_iter(|k| {
            let test = &test;
            (1..ny - 1)
                .flat_map(move |j| (1..nx - 1).filter_map(move |i| test(i + nx * (j + ny * k))))
        })
        .collect()
}

/// The [`CANDIDATES`] shallowest ridge points as (depth, index), ordered
/// by depth then index.
fn ridge_points(g: &Grid, d: &[f64], deepest: f64) -> Vec<(f64, usize)> {
    let [nx, ny, _] = g.dims;
    let (sx, sy) = (1isize, nx as isize);
    let sz = (nx * ny) as isize;
    let mut offsets = Vec::with_capacity(26);
    for dz in -1..=1 {
        for dy in -1..=1 {
            for dx in -1..=1 {
                if (dx, dy, dz) != (0, 0, 0) {
                    offsets.push(dx * sx + dy * sy + dz * sz);
                }
            }
        }
    }
    shallowest(scan(g, |idx| {
        let v = d[idx];
        if v >= 0.0 || -v >= deepest {
            return None;
        }
        let mut inside_neighbour = false;
        for &o in &offsets {
            let w = d[(idx as isize + o) as usize];
            if w < v {
                return None;
            }
            inside_neighbour |= w <= 0.0;
        }
        inside_neighbour.then_some((-v, idx))
    }))
}

/// The [`CANDIDATES`] nearest samples outside, within [`GAP_BAND`]
/// spacings of the surface, whose grid gradient nearly vanishes (see
/// [`GAP_GRADIENT`]), as (distance, index) ordered by distance then index.
fn gap_points(g: &Grid, d: &[f64], bound: bool) -> Vec<(f64, usize)> {
    let [nx, ny, _] = g.dims;
    let strides = [1, nx, nx * ny];
    let band = GAP_BAND * g.h;
    shallowest(scan(g, |idx| {
        let v = d[idx];
        // A gap of at least `2 h` has a sample within `h / 2` of its
        // middle plane, at least `h / 2` from both sides: nearer samples
        // of a distance are the surface's, not a gap's.
        let least = if bound { 0.5 * g.h } else { 0.0 };
        if !(v > least && v <= band) {
            return None;
        }
        let (mut central, mut sides) = (0.0, 0.0);
        for s in strides {
            let (lo, hi) = (d[idx - s], d[idx + s]);
            // Across a gap one side falls to each surface: either neighbour
            // inside means the sample is at the surface, not mid-gap.
            if lo <= 0.0 || hi <= 0.0 {
                return None;
            }
            central += (0.5 * (hi - lo)).powi(2);
            sides += (hi - v).abs().max((v - lo).abs()).powi(2);
        }
        let scale = if bound { g.h * g.h } else { sides };
        (central < GAP_GRADIENT * GAP_GRADIENT * scale).then_some((v, idx))
    }))
}

/// The 13 directions of a cube's axes, face and body diagonals (one of
/// each opposite pair), after the distance's gradient at `p` when it has
/// one.
fn directions(model: &Model, p: DVec3, h: f64) -> Vec<DVec3> {
    let e = h / 4.0;
    let grad = gradient(model, p, e);
    let mut dirs: Vec<DVec3> = Vec::with_capacity(14);
    if let Some(u) = grad.try_normalize() {
        dirs.push(u);
    }
    for z in -1i8..=1 {
        for y in -1i8..=1 {
            for x in -1i8..=1 {
                let v = DVec3::new(f64::from(x), f64::from(y), f64::from(z));
                // One of each opposite pair: the first non-zero component
                // positive.
                let first = [x, y, z].into_iter().find(|&c| c != 0);
                if first == Some(1) {
                    dirs.push(v.normalize());
                }
            }
        }
    }
    dirs
}

/// The distance's central differences at `p`, `e` apart (unscaled).
fn gradient(model: &Model, p: DVec3, e: f64) -> DVec3 {
    DVec3::new(
        model.distance(p + DVec3::X * e) - model.distance(p - DVec3::X * e),
        model.distance(p + DVec3::Y * e) - model.distance(p - DVec3::Y * e),
        model.distance(p + DVec3::Z * e) - model.distance(p - DVec3::Z * e),
    )
}

/// The shortest chord on `side` through `p` along the distance's gradient
/// and the 13 directions of a cube's axes, face and body diagonals (a
/// strut's axis point has no gradient; some of them lie within 20° of any
/// wall's normal), and the nearest exit along them. A gap's chord counts
/// only where it meets both surfaces square (see [`SQUARE`]).
fn thinnest_chord(model: &Model, p: DVec3, h: f64, bound: bool, side: Side) -> (f64, f64) {
    let (mut chord, mut near) = (f64::INFINITY, f64::INFINITY);
    for u in directions(model, p, h) {
        let (a, b) = (
            exit(model, p, u, h, bound, side),
            exit(model, p, -u, h, bound, side),
        );
        near = near.min(a).min(b);
        if a + b < chord
            && (side == Side::Inside
                || [p + u * a, p - u * b].into_iter().all(|q| {
                    gradient(model, q, h / 8.0)
                        .try_normalize()
                        .is_some_and(|n| n.dot(u).abs() >= SQUARE)
                }))
        {
            chord = a + b;
        }
    }
    (chord, near)
}

/// How far from `p` (on `side`) along `u` the surface is: the first
/// sample across it, refined by bisection; the distance travelled when no
/// crossing is found within [`MAX_STEPS`] (a wall that thick counts as
/// thick), or infinity on the outside (empty space that does not end is no
/// gap).
fn exit(model: &Model, p: DVec3, u: DVec3, h: f64, bound: bool, side: Side) -> f64 {
    let min_step = h / 8.0;
    // Outside, a gap's half-chord through a point within the band is at
    // most about the band's width; longer ones are no gap, and stepping
    // through open space past them would cost most of the estimate.
    let reach = match side {
        Side::Inside => f64::INFINITY,
        Side::Outside => 2.0 * GAP_BAND * h,
    };
    let (mut before, mut t) = (0.0, 0.0);
    for _ in 0..MAX_STEPS {
        if t > reach {
            break;
        }
        let v = model.distance(p + u * t);
        if side.crossed(v) {
            let mut after = t;
            for _ in 0..BISECT {
                let mid = 0.5 * (before + after);
                if side.crossed(model.distance(p + u * mid)) {
                    after = mid;
                } else {
                    before = mid;
                }
            }
            return 0.5 * (before + after);
        }
        before = t;
        t += if bound {
            v.abs().max(min_step)
        } else {
            h / 4.0
        };
    }
    match side {
        Side::Inside => t,
        Side::Outside => f64::INFINITY,
    }
}

#[cfg(test)]
mod tests {
    use crate::script::{ScriptOptions, model_of};

    fn sampled(src: &str) -> super::Sampled {
        model_of(src, "t.rhai", &ScriptOptions::default())
            .expect("design prepares")
            .sampled_thinnest()
            .expect("a bounded design")
    }

    #[test]
    fn a_thin_function_plate_is_measured_and_a_fat_sphere_is_not_thin() {
        let s = sampled(
            r#"let m = default_materials();
Intersection(false, [Function("abs(z) - 0.15", m.id("gray")), RectPrism(Vec3(0,0,0), Vec3(10,10,2), m.id("gray"))])"#,
        );
        let f = s.feature.expect("the plate");
        assert!((f.thickness - 0.3).abs() < 0.01, "{f:?} at h {}", s.spacing);
        let s = sampled(r#"Function("x*x+y*y+z*z-25", default_materials().id("gray"))"#);
        let f = s.feature.expect("the ball");
        assert!(f.thickness > 9.0, "{f:?}");
    }

    #[test]
    fn a_slot_between_function_plates_is_a_gap_and_a_concave_corner_is_not() {
        let s = sampled(
            r#"let m = default_materials();
Intersection(false, [Function("0.15 - abs(x)", m.id("gray")), RectPrism(Vec3(0,0,0), Vec3(10,10,4), m.id("gray"))])"#,
        );
        let g = s.gap.expect("the slot");
        assert!((g.thickness - 0.3).abs() < 0.01, "{g:?} at h {}", s.spacing);
        assert!(g.at.x.abs() < s.spacing, "{g:?}");
        // An L: the region where x or y is below zero, in a 10 mm box.
        let s = sampled(
            r#"let m = default_materials();
Intersection(false, [Function("min(x, y)", m.id("gray")), RectPrism(Vec3(0,0,0), Vec3(10,10,4), m.id("gray"))])"#,
        );
        assert_eq!(s.gap, None, "{s:?}");
        assert!(s.feature.is_some());
    }
}
