//! Inlined replacements for two C-library calls in hot loops, `sin_cos`
//! and `floor`, and a cheaper `f64::min` for running minima. On the x86-64
//! baseline (no SSE4.1 rounding instruction) `f64::floor` is a call, and
//! `sin_cos` always is; both show at the top of evaluation profiles
//! (`cargo bench -p volcad-core --bench eval`) of TPMS and tiled lattices.
//! Both give the same bits on every machine and thread count (plain IEEE
//! operations, no FMA contraction), which the C library does not promise
//! across platforms.
//!
//! # `sin_cos`
//! fdlibm's method (Sun Microsystems, 1993; the same kernels as musl and
//! Go): reduce `x` by multiples of π/2 with a two-part π/2 (Cody and
//! Waite), then evaluate the degree-13 and degree-14 minimax polynomials of
//! `__kernel_sin` and `__kernel_cos` on `[−π/4, π/4]`, and pick the pair by
//! the quadrant without a branch. Inlined, with no table and no call, the
//! three pairs of a gyroid point overlap in the pipeline. Accuracy: within
//! 1 ulp of the C library's values (0.5 ulp of 1 measured) for
//! `|x| ≤ REDUCE_MAX`; larger or non-finite arguments go to the C library.
//!
//! # `min_plain`
//! `f64::min` returns the other operand when either is NaN, which takes
//! more work than one `minsd`. A running minimum that starts
//! at +∞ never holds a NaN, so it may use the single compare.
//!
//! # `floor`
//! With SSE4.1 (the x86-64-v2 builds that `.cargo/config.toml` makes, and
//! other architectures) `f64::floor` is one instruction (`roundsd`), used
//! as it is: the truncating version below has branches that are
//! unpredictable in random order. Without SSE4.1:
//! truncation through an integer conversion (one SSE2 instruction each
//! way), minus one where that rounded up; exactly `f64::floor`, signed
//! zeros, infinities and NaN included (tested, both paths on every
//! build).

// The constants are fdlibm's, digit for digit as published (more digits
// than an f64 holds; each rounds to the intended double).
#![allow(clippy::excessive_precision)]

/// Largest `|x|` reduced here: `n·PIO2_HI` stays exact (33 + 20 bits) and
/// the tail's error `n·ulp(PIO2_LO)` stays below 1e−22.
const REDUCE_MAX: f64 = 1.0e6;
const FRAC_2_PI: f64 = std::f64::consts::FRAC_2_PI;
const ROUND: f64 = 6_755_399_441_055_744.0;
/// The first 33 bits of π/2 (fdlibm's `pio2_1`).
const PIO2_HI: f64 = 1.570_796_326_734_125_614_17e+00;
/// π/2 − `PIO2_HI` (fdlibm's `pio2_1t`).
const PIO2_LO: f64 = 6.077_100_506_506_192_249_32e-11;

// fdlibm's __kernel_sin coefficients, then __kernel_cos's: two tables of
// the same shape, not repeated logic.
const S1: f64 = -1.666_666_666_666_663_243_48e-01;
const S2: f64 = 8.333_333_333_322_489_461_24e-03;
const S3: f64 = -1.984_126_982_985_794_931_34e-04;
const S4: f64 = 2.755_731_370_707_006_767_89e-06;
const S5: f64 = -2.505_076_025_340_686_341_95e-08;
const S6: f64 = 1.589_690_995_211_550_102_21e-10;

const C1: f64 = 4.166_666_666_666_660_190_37e-02;
const C2: f64 = -1.388_888_888_887_410_957_49e-03;
const C3: f64 = 2.480_158_728_947_672_941_78e-05;
const C4: f64 = -2.755_731_435_139_066_330_35e-07;
const C5: f64 = 2.087_572_321_298_174_827_90e-09;
const C6: f64 = -1.135_964_755_778_819_482_65e-11;

/// `floor(x)`, bit for bit as `f64::floor`.
#[inline(always)]
pub fn floor(x: f64) -> f64 {
    // With SSE4.1 (x86-64-v2 builds) `f64::floor` is one `roundsd`.
    #[cfg(any(target_feature = "sse4.1", not(target_arch = "x86_64")))]
    {
        x.floor()
    }
    #[cfg(all(target_arch = "x86_64", not(target_feature = "sse4.1")))]
    floor_truncating(x)
}

/// `floor` without SSE4.1's rounding instruction (where `f64::floor` is a
/// call into the C library).
#[inline(always)]
#[cfg_attr(
    any(target_feature = "sse4.1", not(target_arch = "x86_64")),
    allow(dead_code)
)]
fn floor_truncating(x: f64) -> f64 {
    // 2⁵²: from there on every f64 is an integer (and NaN fails the test).
    if x.abs() < 4_503_599_627_370_496.0 {
        let t = x as i64 as f64;
        let f = if t > x { t - 1.0 } else { t };
        // −0.0 truncates to +0.0; floor keeps the zero's sign.
        if f == 0.0 { 0f64.copysign(x) } else { f }
    } else {
        x
    }
}

/// `x.round() as i32` (halves away from zero) for `|x| ≤ 2³⁰`, without
/// the C library's `round` (a call, not an instruction, without SSE4.1):
/// the truncation is exact, and so is `x − t` for such `x`.
#[inline(always)]
pub fn round_i32(x: f64) -> i32 {
    let t = x as i32;
    let f = x - f64::from(t);
    if f >= 0.5 {
        t + 1
    } else if f <= -0.5 {
        t - 1
    } else {
        t
    }
}

/// `floor` of each component.
#[inline(always)]
pub fn floor3(v: glam::DVec3) -> glam::DVec3 {
    glam::DVec3::new(floor(v.x), floor(v.y), floor(v.z))
}

/// `(sin x, cos x)`.
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    // NaN and infinities too: the C library answers those (NaN, NaN).
    if x.is_nan() || x.abs() > REDUCE_MAX {
        return x.sin_cos();
    }
    // Round to nearest by adding and removing 1.5·2⁵² (exact for
    // |x·2/π| < 2⁵¹): `f64::round` is a library call without SSE4.1.
    let n = (x * FRAC_2_PI + ROUND) - ROUND;
    let r = (x - n * PIO2_HI) - n * PIO2_LO;
    let z = r * r;
    // __kernel_sin(r, 0): r + r³·(S1 + z·(S2 + …)).
    let s = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    // __kernel_cos(r, 0): 1 − z/2 + z²·(C1 + z·(C2 + …)), with fdlibm's
    // split of 1 − z/2 that keeps the last bit for |r| > 0.3.
    let p = z * z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    let c = w + (((1.0 - w) - hz) + p);
    // Quadrant q: (s, c), (c, −s), (−s, −c), (−c, s) for q mod 4 = 0..3,
    // chosen without branches (q is as good as random from point to point).
    let q = n as i64;
    let swap = q & 1 != 0;
    let a = if swap { c } else { s };
    let b = if swap { s } else { c };
    let neg = |v: f64, bit: i64| f64::from_bits(v.to_bits() ^ (((bit & 1) as u64) << 63));
    (neg(a, q >> 1), neg(b, (q + 1) >> 1))
}

/// `min(a, b)` for `a` never NaN: `b` when it is smaller, else `a` (a NaN
/// `b` is ignored, as `f64::min` does). One `minsd`: `f64::min` also
/// handles a NaN `a`, which costs more, on the path of
/// every strut a lattice point tests. A running minimum that starts at +∞
/// never holds a NaN.
#[inline(always)]
pub fn min_plain(a: f64, b: f64) -> f64 {
    if b < a { b } else { a }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units in the last place (of the larger magnitude).
    fn ulps(a: f64, b: f64) -> f64 {
        let scale = a.abs().max(b.abs()).max(f64::MIN_POSITIVE);
        (a - b).abs() / (scale * f64::EPSILON)
    }

    #[test]
    fn agrees_with_the_c_library() {
        let mut rng = crate::xorshift::XorShift::new(0x2545_F491_4F6C_DD1Du64);
        let mut next = || rng.next_f64();
        let mut worst = 0.0f64;
        for i in 0..400_000 {
            // Uniform on growing ranges up to REDUCE_MAX, both signs.
            let range = [1.0, 10.0, 1e3, REDUCE_MAX][i % 4];
            let x = (2.0 * next() - 1.0) * range;
            let (s, c) = sin_cos(x);
            let (rs, rc) = x.sin_cos();
            // Absolute error against 1 (values near 0 lose relative
            // precision in any reduction; near 1 they must be exact-ish).
            worst = worst.max((s - rs).abs().max((c - rc).abs()) / f64::EPSILON);
            assert!(s.abs() <= 1.0 && c.abs() <= 1.0, "{x}");
        }
        assert!(worst <= 1.0, "worst {worst} ulp of 1");
        // Near zero the sine is relatively accurate too.
        for x in [1e-300, 1e-20, 1e-8, 0.1, 0.3, std::f64::consts::FRAC_PI_4] {
            let (s, c) = sin_cos(x);
            assert!(ulps(s, x.sin()) <= 1.0 && ulps(c, x.cos()) <= 1.0, "{x}");
        }
    }

    #[test]
    fn round_i32_is_the_c_librarys() {
        let mut rng = crate::xorshift::XorShift::new(5);
        let halves = (-40..=40).map(|k| f64::from(k) * 0.5);
        let near = [0.499_999_999_999_999_94, -2.500_000_000_000_000_4, 1e-300];
        let random = (0..100_000).map(|_| (rng.next_f64() - 0.5) * 2100.0);
        for x in halves.chain(near).chain(random) {
            assert_eq!(round_i32(x), x.round() as i32, "{x}");
        }
    }

    #[test]
    fn floor_is_the_c_librarys() {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            1.5,
            -1.5,
            0.999_999_999_999_999_9,
            -1e-300,
            1e-300,
            4_503_599_627_370_495.5,
            -4_503_599_627_370_495.5,
            4_503_599_627_370_496.0,
            -9.007_199_254_740_993e15,
            1e300,
            -1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
        ];
        for _ in 0..200_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            values.push(f64::from_bits(state)); // every exponent and sign
            values.push((state >> 11) as f64 / (1u64 << 40) as f64 - 4096.0);
        }
        // Both paths, whichever one this build's `floor` takes.
        for x in values {
            let b = x.floor();
            for a in [floor(x), floor_truncating(x)] {
                assert!(
                    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                    "{x:e}"
                );
            }
        }
        assert!(floor(f64::NAN).is_nan() && floor_truncating(f64::NAN).is_nan());
    }

    #[test]
    fn exact_points_signs_and_large_arguments() {
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        for (k, want) in [
            (1.0, (1.0, 0.0)),
            (2.0, (0.0, -1.0)),
            (3.0, (-1.0, 0.0)),
            (-1.0, (-1.0, 0.0)),
        ] {
            let (s, c) = sin_cos(k * std::f64::consts::FRAC_PI_2);
            assert!(
                (s - want.0).abs() < 1e-15 && (c - want.1).abs() < 1e-15,
                "{k}"
            );
        }
        for x in [2e6, -1e300, f64::INFINITY, f64::NAN] {
            let (s, c) = sin_cos(x);
            let (rs, rc) = x.sin_cos();
            assert!(
                s.to_bits() == rs.to_bits() && c.to_bits() == rc.to_bits(),
                "{x}"
            );
        }
    }

    #[test]
    fn min_plain_is_f64_min_for_a_number_first() {
        let values = [
            -3.5,
            -0.0,
            0.0,
            1e-300,
            2.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for a in values.into_iter().filter(|a| !a.is_nan()) {
            for b in values {
                assert_eq!(min_plain(a, b), a.min(b), "min_plain({a}, {b})");
            }
        }
    }
}
