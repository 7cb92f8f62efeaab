//! Random dithering that evaluates fractions only where it must.
//!
//! A voxel's random pick depends on its fractions only through which
//! share `S_j / T` (running sum `S_j = Σ_{i≤j} f_i` over the total) its
//! number `r` falls under (see [`crate::dither`]). In a solid region whose
//! fractions vary smoothly (a grading), bounds of the fractions over a
//! short run of voxels (`Model::fraction_bounds`) leave each share within a
//! narrow band; every voxel whose `r` falls outside the bands gets its pick
//! from the bounds alone, and only the others are evaluated (on the graded
//! bar, runs of 32 voxels at 0.05 mm: about a tenth, tested).
//! The sampler lists such solid tiles as rectangles (`Slab::rects`, with
//! `NaN` fractions; `Consumer::PngStackRandom`) and marks such voxels of
//! tiles a surface crosses with `NaN` fractions.
//!
//! Exactness: the bounds are widened by `crate::dither::BOUND_MARGIN`,
//! which covers rounding the `f64` fractions to `f32` and the `f32` running
//! sums and product that `crate::dither::pick_random` computes, so a
//! decided pick equals the one computed from the evaluated fractions, and
//! the slices are byte for byte those of evaluating every voxel (tested).

use volcad_core::Model;
use volcad_core::interval::Interval;
use volcad_core::model::MAX_MATERIALS;
use volcad_core::sampler::{Grid, RowSpan};

use crate::dither::{BOUND_MARGIN as EPS, MIN_TOTAL, pick_random};
/// Longest run of voxels bounded together (a sampler tile's width).
const RUN: usize = 32;

/// Bounds of the shares `S_j / T` (running sum over total) of one run of
/// voxels. The pick counts the `j` with `S_j ≤ r·T`, i.e. `S_j / T ≤ r`.
/// The share is increasing in the fractions up to `j` and decreasing in the
/// others, so with `P_j = Σ_{i≤j} fᵢ` and `Q_j = Σ_{i>j} fᵢ` it lies within
/// `[P_lo/(P_lo + Q_hi), P_hi/(P_hi + Q_lo)]`. Bounding the share rather
/// than `S_j` and `r·T` apart keeps the total's own uncertainty out: the
/// fractions of a grading sum to 1, which separate bounds cannot know (on
/// the graded bar that tripled the voxels left to evaluate).
struct Shares {
    k: usize,
    lo: [f64; MAX_MATERIALS],
    hi: [f64; MAX_MATERIALS],
}

impl Shares {
    /// No shares yet (filled by [`Shares::set`]; one per row, reused run
    /// after run, so its 1 KB arrays are not built and moved per run).
    const EMPTY: Shares = Shares {
        k: 0,
        lo: [0.0; MAX_MATERIALS],
        hi: [0.0; MAX_MATERIALS],
    };

    /// From fraction bounds; false (and unusable) when the total may be
    /// void.
    fn set(&mut self, bounds: &[Interval]) -> bool {
        let k = bounds.len();
        let total_lo: f64 = bounds.iter().map(|b| b.lo).sum();
        let total_hi: f64 = bounds.iter().map(|b| b.hi).sum();
        if !(total_lo > f64::from(MIN_TOTAL) + EPS && total_hi.is_finite()) {
            return false;
        }
        self.k = k;
        let (mut p_lo, mut p_hi) = (0.0, 0.0);
        for (j, b) in bounds.iter().enumerate() {
            p_lo += b.lo;
            p_hi += b.hi;
            let (q_lo, q_hi) = ((total_lo - p_lo).max(0.0), (total_hi - p_hi).max(0.0));
            self.lo[j] = p_lo / (p_lo + q_hi) - EPS;
            self.hi[j] = p_hi / (p_hi + q_lo) + EPS;
        }
        true
    }

    /// The pick for uniform number `r`, when the bounds settle it.
    #[inline]
    fn pick(&self, r: f32) -> Option<u8> {
        if self.k == 1 {
            return Some(1); // the total is certainly above MIN_TOTAL
        }
        Self::count(&self.lo[..self.k], &self.hi[..self.k], r)
    }

    /// The first `K` bounds by value, rounded outwards to `f32`, for
    /// [`decide`] with `K` known to the compiler: the loop over voxels
    /// vectorises with the bounds in registers. Rounded outwards, they
    /// settle a pick only where the `f64` bounds settle it (the same pick),
    /// and leave a few more open.
    #[inline(always)]
    fn first<const K: usize>(&self) -> ([f32; K], [f32; K]) {
        let down = |x: f64| {
            let y = x as f32;
            if f64::from(y) > x { y.next_down() } else { y }
        };
        let up = |x: f64| {
            let y = x as f32;
            if f64::from(y) < x { y.next_up() } else { y }
        };
        (
            std::array::from_fn(|j| down(self.lo[j])),
            std::array::from_fn(|j| up(self.hi[j])),
        )
    }

    /// The pick from share bounds `lo`, `hi` (one pair a material) when
    /// every share is certainly below or above `r`: `f64` bounds, or the
    /// `f32` ones of [`Shares::first`] (which the run loop vectorises).
    #[inline(always)]
    fn count<F: Copy + PartialOrd + From<f32>>(lo: &[F], hi: &[F], r: f32) -> Option<u8> {
        let r = F::from(r);
        // Without branches (the pick is unpredictable in a mix): count the
        // shares certainly below r, note any that may be on either side.
        let mut pick = 0u8;
        let mut open = false;
        for (lo, hi) in lo.iter().zip(hi) {
            let below = *hi < r;
            let above = *lo > r;
            pick += u8::from(below);
            open |= !(below | above);
        }
        (!open && usize::from(pick) < lo.len()).then_some(pick + 1)
    }
}

/// Most runs a [`RunMemo`] keeps (a kilobyte each): runs that start at
/// the first lazy voxel of a surface tile start anywhere, and a wide grid
/// has many; a full memo starts over.
const MAX_RUNS: usize = 4096;

/// Share bounds of the runs a worker has bounded, by their columns. Where
/// the fractions vary along x alone ([`Model::fraction_axes`]), a run's
/// bounds hold for every run over the same columns, so each row takes
/// those of the rows before it instead of bounding its runs again.
#[derive(Default)]
pub struct RunMemo {
    /// `(first column, end column, shares)`, by columns; `None` where the
    /// bounds could not be used.
    runs: Vec<(usize, usize, Option<Shares>)>,
}

impl RunMemo {
    /// Whether runs of `model` may share their bounds so: its fractions
    /// vary along neither y nor z.
    pub fn applies(model: &Model) -> bool {
        let [_, y, z] = model.fraction_axes();
        !(y || z)
    }

    /// The shares of the run over columns `x0..end`, filled by `fill` (its
    /// success) the first time.
    fn get(
        &mut self,
        x0: usize,
        end: usize,
        fill: impl FnOnce(&mut Shares) -> bool,
    ) -> Option<&Shares> {
        let i = match self.runs.binary_search_by_key(&(x0, end), |r| (r.0, r.1)) {
            Ok(i) => i,
            Err(mut i) => {
                if self.runs.len() >= MAX_RUNS {
                    self.runs.clear();
                    i = 0;
                }
                let mut s = Shares::EMPTY;
                let ok = fill(&mut s);
                self.runs.insert(i, (x0, end, ok.then_some(s)));
                i
            }
        };
        self.runs[i].2.as_ref()
    }
}

/// Random picks for row `y` of layer `z` (`out` and `dist` one per voxel of
/// the row, `fracs` `k` per voxel): as [`crate::dither::choose_random`],
/// with lazy voxels' fractions bounded per run and evaluated only where
/// the bounds leave the pick open. Lazy: the voxels of `lazy_spans` (the
/// row's runs of the sampler's lazy rectangles, whose entries in `fracs`
/// are not written) and inside voxels whose fractions are `NaN`. `memo`:
/// the worker's bounded runs, only where the model's fractions vary along
/// x alone. Returns how many lazy voxels were evaluated.
#[allow(clippy::too_many_arguments)]
pub fn choose_random_row(
    model: &Model,
    grid: &Grid,
    seed: u64,
    [y, z]: [usize; 2],
    dist: &[f32],
    fracs: &[f32],
    k: usize,
    lazy_spans: &[RowSpan],
    out: &mut [u8],
    memo: Option<&mut RunMemo>,
) -> usize {
    let nx = grid.dims[0];
    let mut row = Row {
        model,
        grid,
        seed,
        yz: [y, z],
        dist,
        fracs,
        k,
        iv: [Interval::point(0.0); MAX_MATERIALS],
        f: [0.0; MAX_MATERIALS],
        f32s: [0.0; MAX_MATERIALS],
        shares: Shares::EMPTY,
        memo,
        evaluated: 0,
    };
    // Outside the rectangles, an inside voxel marked `NaN` is lazy.
    let marked = |v: usize| dist[v] <= 0.0 && fracs[v * k].is_nan();
    let mut x = 0;
    for s in lazy_spans {
        let (a, b) = (s.x0.clamp(x, nx), s.x1.clamp(x, nx));
        row.picks(x..a, out, marked);
        // (A rectangle's voxels are solid.)
        row.picks(a..b, out, |_| true);
        x = x.max(b);
    }
    row.picks(x..nx, out, marked);
    row.evaluated
}

/// One row's inputs and scratch for [`choose_random_row`].
struct Row<'a> {
    model: &'a Model,
    grid: &'a Grid,
    seed: u64,
    yz: [usize; 2],
    dist: &'a [f32],
    fracs: &'a [f32],
    k: usize,
    iv: [Interval; MAX_MATERIALS],
    f: [f64; MAX_MATERIALS],
    f32s: [f32; MAX_MATERIALS],
    shares: Shares,
    memo: Option<&'a mut RunMemo>,
    evaluated: usize,
}

impl Row<'_> {
    /// The picks of voxels `xs` into `out` (the whole row's), `lazy(v)`
    /// telling which are lazy.
    #[inline(always)]
    fn picks(&mut self, xs: std::ops::Range<usize>, out: &mut [u8], lazy: impl Fn(usize) -> bool) {
        let (k, [y, z]) = (self.k, self.yz);
        let [nx, ny, _] = self.grid.dims;
        let first = ((z * ny + y) * nx) as u64;
        let mut x = xs.start;
        while x < xs.end {
            if !lazy(x) {
                let end = (x + 1..xs.end).find(|&e| lazy(e)).unwrap_or(xs.end);
                crate::dither::choose_random(
                    self.seed,
                    first + x as u64,
                    &self.dist[x..end],
                    &self.fracs[x * k..end * k],
                    k,
                    &mut out[x..end],
                );
                x = end;
                continue;
            }
            let end = (x + 1..(x + RUN).min(xs.end))
                .find(|&e| !lazy(e))
                .unwrap_or((x + RUN).min(xs.end));
            let b =
                volcad_core::Aabb::new(self.grid.center(x, y, z), self.grid.center(end - 1, y, z));
            let (model, iv) = (self.model, &mut self.iv);
            let sums = match &mut self.memo {
                Some(m) => m.get(x, end, |s| {
                    model.fraction_bounds(&b, &mut iv[..k]) && s.set(&iv[..k])
                }),
                None => (model.fraction_bounds(&b, &mut iv[..k]) && self.shares.set(&iv[..k]))
                    .then_some(&self.shares),
            };
            let (grid, evaluated) = (self.grid, &mut self.evaluated);
            let (f, f32s) = (&mut self.f, &mut self.f32s);
            let x0 = x;
            let mut open = |i: usize, r: f32| {
                let v = x0 + i;
                *evaluated += 1;
                model.fractions_inside(grid.center(v, y, z), &mut f[..k]);
                for (a, b) in f32s.iter_mut().zip(&f[..k]) {
                    *a = *b as f32;
                }
                pick_random(&f32s[..k], r)
            };
            let (seed, out) = (self.seed, &mut out[x..end]);
            match (sums, k) {
                (Some(s), 2) => run_k::<2>(s, seed, first + x as u64, out, &mut open),
                (Some(s), 3) => run_k::<3>(s, seed, first + x as u64, out, &mut open),
                (Some(s), _) => run(seed, first + x as u64, out, |r| s.pick(r), &mut open),
                (None, _) => run(seed, first + x as u64, out, |_| None, &mut open),
            }
            x = end;
        }
    }
}

/// Picks for one run of voxels, the first with global index `first`: from
/// the bounds where `decide(r)` settles them, else from `open(i, r)` (`i`
/// the voxel's place in the run).
#[inline(always)]
fn run(
    seed: u64,
    first: u64,
    out: &mut [u8],
    decide: impl Fn(f32) -> Option<u8>,
    open: &mut impl FnMut(usize, f32) -> u8,
) {
    crate::draws::each(seed, first, out.len(), |i, r| {
        out[i] = match decide(r) {
            Some(code) => code,
            None => open(i, r),
        };
    });
}

/// [`run`] deciding from `K` shares held by value (see [`Shares::first`]):
/// every voxel's pick from the bounds first, in one loop with no call or
/// branch that vectorises (0 where they leave it open), then the open
/// ones evaluated.
#[inline(always)]
fn run_k<const K: usize>(
    s: &Shares,
    seed: u64,
    first: u64,
    out: &mut [u8],
    open: &mut impl FnMut(usize, f32) -> u8,
) {
    let (lo, hi) = s.first::<K>();
    for (at, key, low, len) in crate::draws::pieces(seed, first, out.len()) {
        let part = &mut out[at..at + len];
        decide::<K>(&lo, &hi, key, low, part);
        for (i, o) in part.iter_mut().enumerate() {
            if *o == 0 {
                *o = open(at + i, crate::draws::nth(key, low, i));
            }
        }
    }
}

/// The picks the share bounds `lo`, `hi` settle for the voxels drawing
/// with `key` from low index `low` on, 0 for those they leave open.
#[inline(always)]
fn decide<const K: usize>(lo: &[f32; K], hi: &[f32; K], key: u32, low: u32, out: &mut [u8]) {
    for (i, o) in out.iter_mut().enumerate() {
        *o = Shares::count(lo, hi, crate::draws::nth(key, low, i)).unwrap_or(0);
    }
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::AtomicBool;

    use glam::DVec3;
    use volcad_core::sampler::{Consumer, Sampler, Slab};
    use volcad_core::script::model_of_file;

    use super::*;
    use crate::mesh::tests::model;

    /// Codes of every layer of `m` at `voxel`, sampling every voxel and
    /// lazily: they must be equal.
    /// Returns the voxels left lazy, those of them evaluated after all, and
    /// the inside voxels.
    fn compare(m: &Model, voxel: f64, seed: u64) -> (usize, usize, usize) {
        let grid = Grid::covering(&m.bbox(), DVec3::splat(voxel), 1 << 40).expect("grid");
        let [nx, ny, nz] = grid.dims;
        let k = m.materials().len();
        let cancel = AtomicBool::new(false);
        let eager = Sampler::new(m, grid, Consumer::PngStackDiffusion);
        let lazy = Sampler::new(m, grid, Consumer::PngStackRandom);
        let (mut a, mut b) = (Slab::default(), Slab::default());
        let (mut ca, mut cb) = (vec![0u8; nx], vec![0u8; nx]);
        let (mut marked, mut evaluated, mut inside) = (0, 0, 0);
        let mut memo = RunMemo::default();
        let shared = RunMemo::applies(m);
        // Stale fractions in the reused buffer must not matter where the
        // lazy sampler lists rectangles.
        b.fracs = vec![0.25; nx * ny * k];
        for z in 0..nz {
            eager
                .sample_layers(z, z + 1, &mut a, &cancel)
                .expect("sample");
            lazy.sample_layers(z, z + 1, &mut b, &cancel)
                .expect("sample");
            let rows = b.rect_rows(z, nx, ny);
            for y in 0..ny {
                let (d, f) = (&a.dist[y * nx..][..nx], &a.fracs[y * nx * k..][..nx * k]);
                crate::dither::choose_random(seed, ((z * ny + y) * nx) as u64, d, f, k, &mut ca);
                let (d, f) = (&b.dist[y * nx..][..nx], &b.fracs[y * nx * k..][..nx * k]);
                let spans = rows.row(y);
                let memo = shared.then_some(&mut memo);
                evaluated +=
                    choose_random_row(m, &grid, seed, [y, z], d, f, k, spans, &mut cb, memo);
                assert_eq!(ca, cb, "row {y} of layer {z}");
                marked += (0..nx)
                    .filter(|&x| {
                        f[x * k].is_nan() || spans.iter().any(|s| (s.x0..s.x1).contains(&x))
                    })
                    .count();
                inside += ca.iter().filter(|&&c| c > 0).count();
            }
        }
        (marked, evaluated, inside)
    }

    #[test]
    fn a_memo_of_many_runs_stays_bounded_and_answers_each() {
        let mut memo = RunMemo::default();
        for x0 in 0..3 * MAX_RUNS {
            let s = memo.get(x0, x0 + 7, |s| {
                s.k = 2;
                s.lo[0] = x0 as f64;
                true
            });
            assert_eq!(s.map(|s| s.lo[0]), Some(x0 as f64));
            assert!(memo.runs.len() <= MAX_RUNS);
        }
        // Kept runs are answered without filling again.
        let last = 3 * MAX_RUNS - 1;
        let again = memo.get(last, last + 7, |_| panic!("filled twice"));
        assert_eq!(again.map(|s| s.lo[0]), Some(last as f64));
    }

    #[test]
    fn lazy_picks_equal_evaluated_ones() {
        let designs = [
            r#"FGrade(["x/15+0.5", "-x/15+0.5"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(15,10,5), m.id("gray")))"#,
            r#"Rotate(10, 20, 30, Vec3(0,0,0), FGrade(["x*x/20", "0.3", "1 - y/8", "z/4 + 0.5"], [m.id("red"), m.id("green"), m.id("blue"), m.id("yellow")], true, Sphere(Vec3(0,0,0), 4, m.id("gray"))))"#,
            // A grade that reaches zero total: void inside the shape.
            r#"FGrade(["x", "0"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(6,4,4), m.id("gray")))"#,
            // Graded along y: each row's runs have bounds of their own (a
            // run sharing another row's would pick wrongly).
            r#"FGrade(["y/60+0.5", "-y/60+0.5"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(15,10,5), m.id("gray")))"#,
            // Three materials (the picks' other unrolled case; two and
            // four are above).
            r#"FGrade(["x/15+0.5", "0.2", "-x/15+0.5"], [m.id("red"), m.id("green"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(15,10,5), m.id("gray")))"#,
        ];
        for src in designs {
            let m = model(src);
            for seed in [1, 99] {
                let (marked, evaluated, inside) = compare(&m, 0.1, seed);
                assert!(marked > inside / 4, "{src}: {marked} of {inside} lazy");
                assert!(evaluated < marked, "{src}: all {marked} evaluated");
            }
        }
        // The graded bar at 0.05 mm (a run is 1.6 mm, a tenth of the
        // grading): bounds settle about nine lazy voxels in ten. Bounding
        // running sums and the total apart left a third open.
        let bar = model(designs[0]);
        let (marked, evaluated, _) = compare(&bar, 0.05, 1);
        eprintln!("graded bar at 0.05 mm: {evaluated} of {marked} lazy voxels evaluated");
        assert!(evaluated * 8 < marked, "{evaluated} of {marked} evaluated");
        // Blended fractions (125 or 216 samples a voxel) are left lazy in tiles a
        // surface crosses too: a thin shell is mostly such tiles.
        let blend = model(
            r#"Blend(0.8, Shell(-1.0, Union(1.0, false, [Sphere(Vec3(-2,0,0), 4, m.id("red")), Sphere(Vec3(2,0,0), 4, m.id("blue"))])))"#,
        );
        let (marked, evaluated, inside) = compare(&blend, 0.1, 3);
        assert!(marked * 4 > inside, "{marked} of {inside} lazy");
        assert!(evaluated * 2 < marked, "{evaluated} of {marked} evaluated");
    }

    #[test]
    fn lazy_picks_of_the_seat_field_equal_evaluated_ones() {
        let m = model_of_file(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../assets/examples/bicycle_seat.rhai"),
        )
        .expect("seat");
        let (marked, evaluated, inside) = compare(&m, 1.0, 3);
        assert!(marked > inside / 10, "{marked} of {inside} lazy");
        assert!(evaluated < marked, "all {marked} evaluated");
    }

    #[test]
    fn bounds_settle_most_picks_of_a_gentle_grade() {
        let mut iv = [Interval::point(0.0); 2];
        iv[0] = Interval::new(0.40, 0.41);
        iv[1] = Interval::new(0.59, 0.60);
        let mut s = Shares::EMPTY;
        assert!(s.set(&iv), "not void");
        let settled = (0..1000)
            .filter(|i| s.pick(*i as f32 / 1000.0).is_some())
            .count();
        assert!(settled > 950, "{settled}");
        assert_eq!(s.pick(0.1), Some(1));
        assert_eq!(s.pick(0.9), Some(2));
        assert_eq!(s.pick(0.405), None);
    }
}
