//! Interval arithmetic: conservative bounds on a value over a range of inputs.
//!
//! An [`Interval`] `[lo, hi]` stands for every real number between its bounds. Every
//! operation here is *conservative*: if `a ∈ A` and `b ∈ B` then `a ∘ b ∈ A ∘ B`, where
//! `a ∘ b` is the same `f64` computation the scalar evaluator performs. Octree pruning
//! and material-grading range checks rely on this: a cell whose interval is entirely
//! positive can be skipped without sampling it.
//!
//! # NaN
//!
//! An interval cannot hold NaN. Whenever some input point could produce NaN (`0 * inf`,
//! `sqrt(-1)`, `inf - inf`, `sin(inf)`, ...) the result is [`Interval::EVERYTHING`], and
//! every consumer treats `EVERYTHING` as "may also be NaN". [`Interval::new`] maps NaN
//! bounds to `EVERYTHING`, so that rule mostly falls out of the arithmetic.
//!
//! # Warning
//!
//! No directed rounding is used. Bounds are computed with the same round-to-nearest
//! operations as the scalar evaluator; correctly rounded operations (`+ - * /`, `sqrt`)
//! are monotone, so the bounds still contain every value the scalar evaluator can
//! produce. Transcendental functions (`exp`, `sin`, ...) are only faithfully rounded,
//! so their bounds are widened outward by two ulps. The bounds are therefore valid for
//! the floating-point evaluator, not necessarily for the exact real-number function.

use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A closed range `[lo, hi]` of real numbers, with `lo <= hi` (bounds may be infinite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Lower bound (may be `-inf`).
    pub lo: f64,
    /// Upper bound (may be `+inf`).
    pub hi: f64,
}

/// Largest `|x|` for which the trigonometric bounds find the extrema by dividing by the
/// period; beyond it the period arithmetic loses precision and `[-1, 1]` is returned.
const TRIG_MAX_ARG: f64 = 1e6;

/// Slack, in periods, when deciding whether an interval contains a trig extremum or
/// pole: erring towards "contains" only loosens the bounds, never breaks them.
const TRIG_SLACK: f64 = 1e-9;

impl Interval {
    /// `[-inf, inf]`: nothing is known, and the value may also be NaN.
    pub const EVERYTHING: Interval = Interval {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    /// `[0, 1]`: the result of an undecided comparison or logical operator.
    pub const UNDECIDED: Interval = Interval { lo: 0.0, hi: 1.0 };

    /// Builds `[lo, hi]`. A NaN bound means "anything, maybe NaN" and gives
    /// [`Interval::EVERYTHING`].
    ///
    /// In debug builds, panics when `lo > hi`.
    #[inline]
    pub fn new(lo: f64, hi: f64) -> Self {
        if lo.is_nan() || hi.is_nan() {
            return Self::EVERYTHING;
        }
        debug_assert!(lo <= hi, "Interval::new({lo}, {hi}): lo > hi");
        Self { lo, hi }
    }

    /// The degenerate interval `[v, v]` (NaN gives [`Interval::EVERYTHING`]).
    #[inline]
    pub fn point(v: f64) -> Self {
        Self::new(v, v)
    }

    /// `hi - lo` (infinite for unbounded intervals).
    #[inline]
    pub fn width(&self) -> f64 {
        self.hi - self.lo
    }

    /// Midpoint, computed as `lo/2 + hi/2` so it never overflows; `0` for
    /// [`Interval::EVERYTHING`], the infinite bound for half-unbounded intervals.
    #[inline]
    pub fn mid(&self) -> f64 {
        if self.is_everything() {
            0.0
        } else {
            self.lo * 0.5 + self.hi * 0.5
        }
    }

    /// Whether `lo <= v <= hi` (false for NaN).
    #[inline]
    pub fn contains(&self, v: f64) -> bool {
        self.lo <= v && v <= self.hi
    }

    /// Whether this is `[-inf, inf]`, which also stands for "may be NaN".
    #[inline]
    pub fn is_everything(&self) -> bool {
        self.lo == f64::NEG_INFINITY && self.hi == f64::INFINITY
    }

    /// Whether `lo == hi`.
    #[inline]
    pub fn is_point(&self) -> bool {
        self.lo == self.hi
    }

    /// Convex hull: the smallest interval containing both.
    #[inline]
    pub fn union(self, o: Self) -> Self {
        Self {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    /// Bounds of `min(a, b)`: `[min(a.lo, b.lo), min(a.hi, b.hi)]`.
    #[inline]
    pub fn min(self, o: Self) -> Self {
        Self {
            lo: self.lo.min(o.lo),
            hi: self.hi.min(o.hi),
        }
    }

    /// Bounds of `max(a, b)`: `[max(a.lo, b.lo), max(a.hi, b.hi)]`.
    #[inline]
    pub fn max(self, o: Self) -> Self {
        Self {
            lo: self.lo.max(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    /// Bounds of `-x`: `[-hi, -lo]`. (Also available as the `-` operator; the
    /// inherent method works without importing `std::ops::Neg`.)
    #[inline]
    #[allow(clippy::should_implement_trait)]
    pub fn neg(self) -> Self {
        Self {
            lo: -self.hi,
            hi: -self.lo,
        }
    }

    /// Bounds of `|x|`: `[0, max(-lo, hi)]` when the interval straddles zero.
    #[inline]
    pub fn abs(self) -> Self {
        if self.is_everything() || self.lo >= 0.0 {
            self
        } else if self.hi <= 0.0 {
            self.neg()
        } else {
            Self {
                lo: 0.0,
                hi: (-self.lo).max(self.hi),
            }
        }
    }

    /// Smallest `|x|` in the interval (the "mignitude").
    #[inline]
    pub fn mig(&self) -> f64 {
        if self.lo >= 0.0 {
            self.lo
        } else if self.hi <= 0.0 {
            -self.hi
        } else {
            0.0
        }
    }

    /// Largest `|x|` in the interval (the "magnitude").
    #[inline]
    pub fn mag(&self) -> f64 {
        (-self.lo).max(self.hi)
    }

    /// Bounds of `x * x`; unlike `x * x` on intervals, knows both factors are equal,
    /// so `[-1, 2].square()` is `[0, 4]` rather than `[-2, 4]`.
    #[inline]
    pub fn square(self) -> Self {
        if self.is_everything() {
            return self;
        }
        let (m, big) = (self.mig(), self.mag());
        Self::new(m * m, big * big)
    }

    /// Bounds of `sqrt(x)`; `EVERYTHING` when the interval reaches below zero (NaN).
    #[inline]
    pub fn sqrt(self) -> Self {
        if self.lo < 0.0 {
            Self::EVERYTHING
        } else {
            Self::new(self.lo.sqrt(), self.hi.sqrt())
        }
    }

    /// Bounds of `e^x` (monotone increasing, never below 0).
    pub fn exp(self) -> Self {
        self.increasing(f64::exp).clamp_to(0.0, f64::INFINITY)
    }

    /// Bounds of the natural logarithm; `EVERYTHING` if the interval reaches below 0.
    pub fn ln(self) -> Self {
        if self.lo < 0.0 {
            Self::EVERYTHING
        } else {
            self.increasing(f64::ln)
        }
    }

    /// Bounds of `f(x)` for a non-decreasing, faithfully rounded `f` with
    /// `f(NaN) = NaN`: `[f(lo), f(hi)]` widened outward by two ulps.
    #[inline]
    pub fn increasing(self, f: impl Fn(f64) -> f64) -> Self {
        if self.is_everything() {
            return self;
        }
        widen(f(self.lo), f(self.hi))
    }

    /// Bounds of `f(x)` for a non-increasing, faithfully rounded `f` with
    /// `f(NaN) = NaN`: `[f(hi), f(lo)]` widened outward by two ulps.
    #[inline]
    pub fn decreasing(self, f: impl Fn(f64) -> f64) -> Self {
        if self.is_everything() {
            return self;
        }
        widen(f(self.hi), f(self.lo))
    }

    /// Intersection with `[lo, hi]`, for functions whose range is known to lie there
    /// (keeps widened bounds of `sin` inside `[-1, 1]`). `EVERYTHING` is kept as is,
    /// since it may stand for NaN.
    #[inline]
    pub fn clamp_to(self, lo: f64, hi: f64) -> Self {
        if self.is_everything() {
            self
        } else {
            Self::new(self.lo.max(lo).min(hi), self.hi.min(hi).max(lo))
        }
    }

    /// Bounds of `sin(x)`.
    ///
    /// `sin` peaks at `π/2 + 2kπ` and bottoms out at `-π/2 + 2kπ`; elsewhere the
    /// extremes are at the endpoints. Intervals `2π` or wider give `[-1, 1]`; infinite
    /// bounds give `EVERYTHING` because `sin(±inf)` is NaN.
    pub fn sin(self) -> Self {
        self.periodic(f64::sin, FRAC_PI_2, -FRAC_PI_2)
    }

    /// Bounds of `cos(x)`: maxima at `2kπ`, minima at `π + 2kπ` (see [`Interval::sin`]).
    pub fn cos(self) -> Self {
        self.periodic(f64::cos, 0.0, PI)
    }

    fn periodic(self, f: fn(f64) -> f64, max_at: f64, min_at: f64) -> Self {
        if !(self.lo.is_finite() && self.hi.is_finite()) {
            return Self::EVERYTHING;
        }
        if self.width() >= TAU || self.mag() > TRIG_MAX_ARG {
            return Self::new(-1.0, 1.0);
        }
        let (a, b) = (f(self.lo), f(self.hi));
        let mut lo = a.min(b);
        let mut hi = a.max(b);
        if self.contains_phase(max_at, TAU) {
            hi = 1.0;
        }
        if self.contains_phase(min_at, TAU) {
            lo = -1.0;
        }
        widen(lo, hi).clamp_to(-1.0, 1.0)
    }

    /// Bounds of `tan(x)`: monotone between the poles at `π/2 + kπ`; an interval that
    /// contains (or nearly touches) a pole gives `EVERYTHING`.
    pub fn tan(self) -> Self {
        if !(self.lo.is_finite() && self.hi.is_finite())
            || self.width() >= PI
            || self.mag() > TRIG_MAX_ARG
            || self.contains_phase(FRAC_PI_2, PI)
        {
            return Self::EVERYTHING;
        }
        self.increasing(f64::tan)
    }

    /// Whether some `phase + k·period` (integer `k`) lies in the interval, erring
    /// towards `true` by [`TRIG_SLACK`] periods.
    fn contains_phase(&self, phase: f64, period: f64) -> bool {
        let k0 = ((self.lo - phase) / period - TRIG_SLACK).ceil();
        let k1 = ((self.hi - phase) / period + TRIG_SLACK).floor();
        k0 <= k1
    }
}

/// `[lo, hi]` widened outward by two ulps on each side (absorbs the up-to-one-ulp error
/// of a faithfully rounded function at both the endpoint and the sample).
#[inline]
pub(crate) fn widen(lo: f64, hi: f64) -> Interval {
    Interval::new(lo.next_down().next_down(), hi.next_up().next_up())
}

impl From<f64> for Interval {
    #[inline]
    fn from(v: f64) -> Self {
        Interval::point(v)
    }
}

impl Neg for Interval {
    type Output = Interval;
    #[inline]
    fn neg(self) -> Interval {
        Interval::neg(self)
    }
}

impl Add for Interval {
    type Output = Interval;
    /// `[a.lo + b.lo, a.hi + b.hi]`; `inf + -inf` gives `EVERYTHING`.
    #[inline]
    fn add(self, o: Interval) -> Interval {
        Interval::new(self.lo + o.lo, self.hi + o.hi)
    }
}

impl Sub for Interval {
    type Output = Interval;
    /// `[a.lo - b.hi, a.hi - b.lo]`; `inf - inf` gives `EVERYTHING`.
    #[inline]
    fn sub(self, o: Interval) -> Interval {
        Interval::new(self.lo - o.hi, self.hi - o.lo)
    }
}

impl Mul for Interval {
    type Output = Interval;
    /// Hull of the four corner products; `0 * inf` at a corner gives `EVERYTHING`.
    #[inline]
    fn mul(self, o: Interval) -> Interval {
        corners(self, o, |a, b| a * b)
    }
}

impl Div for Interval {
    type Output = Interval;
    /// Hull of the four corner quotients when the divisor excludes zero; a divisor
    /// containing zero gives `EVERYTHING` (the quotient is unbounded or NaN).
    #[inline]
    fn div(self, o: Interval) -> Interval {
        if o.lo <= 0.0 && o.hi >= 0.0 {
            Interval::EVERYTHING
        } else {
            corners(self, o, |a, b| a / b)
        }
    }
}

/// Hull of `f` at the four corners of `a × b`; valid for any `f` that is monotone in
/// each argument separately on the box. A NaN corner gives `EVERYTHING`.
#[inline]
pub(crate) fn corners(a: Interval, b: Interval, f: impl Fn(f64, f64) -> f64) -> Interval {
    let p0 = f(a.lo, b.lo);
    let p1 = f(a.lo, b.hi);
    let p2 = f(a.hi, b.lo);
    let p3 = f(a.hi, b.hi);
    if p0.is_nan() || p1.is_nan() || p2.is_nan() || p3.is_nan() {
        return Interval::EVERYTHING;
    }
    Interval {
        lo: p0.min(p1).min(p2.min(p3)),
        hi: p0.max(p1).max(p2.max(p3)),
    }
}

macro_rules! scalar_ops {
    ($($tr:ident $f:ident),*) => {$(
        impl $tr<f64> for Interval {
            type Output = Interval;
            #[inline]
            fn $f(self, o: f64) -> Interval {
                $tr::$f(self, Interval::point(o))
            }
        }
        impl $tr<Interval> for f64 {
            type Output = Interval;
            #[inline]
            fn $f(self, o: Interval) -> Interval {
                $tr::$f(Interval::point(self), o)
            }
        }
    )*};
}
scalar_ops!(Add add, Sub sub, Mul mul, Div div);

#[cfg(test)]
pub(crate) mod test_rng {
    //! Random intervals for the interval arithmetic tests here and in
    //! `expr::interval_eval`.

    use super::Interval;

    /// Random intervals (points, half-lines, everything, ranges of mixed
    /// scale) and points in them, from a deterministic xorshift generator so
    /// a failure reproduces: for the tests that check interval arithmetic
    /// contains every value it bounds.
    pub(crate) struct IntervalRng(crate::xorshift::XorShift);

    impl IntervalRng {
        /// The generator started from `seed`.
        pub(crate) fn new(seed: u64) -> Self {
            Self(crate::xorshift::XorShift::new(seed))
        }
        pub(crate) fn unit(&mut self) -> f64 {
            self.0.next_f64()
        }
        pub(crate) fn pick<T: Copy>(&mut self, xs: &[T]) -> T {
            xs[((self.unit() * xs.len() as f64) as usize).min(xs.len() - 1)]
        }
        pub(crate) fn value(&mut self) -> f64 {
            let scale = self.pick(&[0.01, 1.0, 1.5, 4.0, 20.0, 1e4]);
            match (self.unit() * 8.0) as u32 {
                0 => self.pick(&[0.0, -0.0, 1.0, -1.0, 2.0, 3.0, 0.5, -2.0]),
                _ => (self.unit() - 0.5) * 2.0 * scale,
            }
        }
        pub(crate) fn interval(&mut self) -> Interval {
            let (a, b) = (self.value(), self.value());
            match (self.unit() * 14.0) as u32 {
                0 | 1 => Interval::point(a),
                2 => Interval::new(a.min(b), f64::INFINITY),
                3 => Interval::new(f64::NEG_INFINITY, a.max(b)),
                4 => Interval::EVERYTHING,
                5 => Interval::new(a.abs().min(b.abs()), a.abs().max(b.abs())),
                _ => Interval::new(a.min(b), a.max(b)),
            }
        }
        pub(crate) fn sample(&mut self, i: Interval) -> f64 {
            if i.is_everything() && self.unit() < 0.2 {
                return f64::NAN;
            }
            match (self.unit() * 6.0) as u32 {
                0 => i.lo,
                1 => i.hi,
                _ => {
                    let spread = 10f64.powf(self.unit() * 6.0 - 2.0);
                    if i.lo.is_finite() && i.hi.is_finite() {
                        (i.lo + (i.hi - i.lo) * self.unit()).clamp(i.lo, i.hi)
                    } else if i.lo.is_finite() {
                        i.lo + spread
                    } else if i.hi.is_finite() {
                        i.hi - spread
                    } else {
                        (self.unit() - 0.5) * spread
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::test_rng::IntervalRng;
    use super::*;

    fn check(out: Interval, v: f64, what: &str) {
        if v.is_nan() {
            assert!(out.is_everything(), "{what}: NaN result but bounds {out:?}");
        } else {
            assert!(out.contains(v), "{what}: {v} not in {out:?}");
        }
    }

    #[test]
    fn basics() {
        let a = Interval::new(-1.0, 2.0);
        assert_eq!(a.width(), 3.0);
        assert_eq!(a.mid(), 0.5);
        assert!(a.contains(0.0) && !a.contains(2.5) && !a.contains(f64::NAN));
        assert_eq!(Interval::EVERYTHING.mid(), 0.0);
        assert_eq!(Interval::new(f64::NAN, 1.0), Interval::EVERYTHING);
        assert_eq!(a.square(), Interval::new(0.0, 4.0));
        assert_eq!(a.abs(), Interval::new(0.0, 2.0));
        assert_eq!(-a, Interval::new(-2.0, 1.0));
        assert_eq!(a + 1.0, Interval::new(0.0, 3.0));
        assert_eq!(2.0 * a, Interval::new(-2.0, 4.0));
        assert_eq!(a * a, Interval::new(-2.0, 4.0));
        assert_eq!(1.0 / a, Interval::EVERYTHING);
        assert_eq!(
            Interval::new(1.0, 2.0) / Interval::new(2.0, 4.0),
            Interval::new(0.25, 1.0)
        );
        assert_eq!(a.union(Interval::point(5.0)), Interval::new(-1.0, 5.0));
        assert_eq!(a.min(Interval::point(0.0)), Interval::new(-1.0, 0.0));
        assert_eq!(a.max(Interval::point(0.0)), Interval::new(0.0, 2.0));
        assert_eq!(a.sqrt(), Interval::EVERYTHING);
        assert_eq!(Interval::new(4.0, 9.0).sqrt(), Interval::new(2.0, 3.0));
        assert_eq!(Interval::new(0.0, TAU).sin(), Interval::new(-1.0, 1.0));
        let s = Interval::new(0.1, 0.2).sin();
        assert!(s.lo > 0.09 && s.hi < 0.2);
        assert_eq!(Interval::new(1.0, 2.0).tan(), Interval::EVERYTHING);
        assert_eq!(
            Interval::new(0.0, f64::INFINITY).sin(),
            Interval::EVERYTHING
        );
        let inf = Interval::new(1.0, f64::INFINITY);
        assert_eq!(inf - inf, Interval::EVERYTHING);
        assert_eq!(Interval::new(0.0, 1.0) * inf, Interval::EVERYTHING);
    }

    #[test]
    fn containment() {
        type Un = (&'static str, fn(Interval) -> Interval, fn(f64) -> f64);
        type Bin = (
            &'static str,
            fn(Interval, Interval) -> Interval,
            fn(f64, f64) -> f64,
        );
        let unary: [Un; 8] = [
            ("neg", |i| -i, |v| -v),
            ("abs", Interval::abs, f64::abs),
            ("square", Interval::square, |v| v * v),
            ("sqrt", Interval::sqrt, f64::sqrt),
            ("exp", Interval::exp, f64::exp),
            ("ln", Interval::ln, f64::ln),
            ("sin", Interval::sin, f64::sin),
            ("cos", Interval::cos, f64::cos),
        ];
        let binary: [Bin; 6] = [
            ("add", |a, b| a + b, |a, b| a + b),
            ("sub", |a, b| a - b, |a, b| a - b),
            ("mul", |a, b| a * b, |a, b| a * b),
            ("div", |a, b| a / b, |a, b| a / b),
            ("min", Interval::min, f64::min),
            ("max", Interval::max, f64::max),
        ];
        let mut rng = IntervalRng::new(0x9E37_79B9_7F4A_7C15);
        for _ in 0..3000 {
            let (a, b) = (rng.interval(), rng.interval());
            for (name, fi, fs) in unary {
                let out = fi(a);
                for _ in 0..8 {
                    let v = rng.sample(a);
                    check(out, fs(v), &format!("{name}({v}) over {a:?}"));
                }
            }
            let tan = a.tan();
            for _ in 0..8 {
                let v = rng.sample(a);
                check(tan, v.tan(), &format!("tan({v}) over {a:?}"));
            }
            for (name, fi, fs) in binary {
                let out = fi(a, b);
                for _ in 0..8 {
                    let (x, y) = (rng.sample(a), rng.sample(b));
                    check(out, fs(x, y), &format!("{name}({x}, {y}) over {a:?} {b:?}"));
                }
            }
        }
    }
}
