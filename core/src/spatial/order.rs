//! Integer sort keys for `f32`s that order exactly as [`f32::total_cmp`].
//!
//! Why: the candidate grid and the union index sort hundreds of thousands
//! of short lists by an `f32` bound, ties broken by an index. Through
//! `total_cmp(..).then(..)` a comparison takes two branches; one `u64` key per entry (the bound's order-preserving bits
//! above the index) makes it one compare, and the same order.
//!
//! The map is `total_cmp`'s own: flip the low 31 bits of a negative
//! number, so that its magnitude counts down, then flip the sign bit, so
//! that negatives come before positives.

/// `u32`s in the order [`f32::total_cmp`] puts their floats in.
#[inline(always)]
pub fn f32_key(x: f32) -> u32 {
    let b = x.to_bits();
    let neg = ((b as i32) >> 31) as u32; // all ones for a negative number
    (b ^ (neg >> 1)) ^ 0x8000_0000
}

/// The key of `(x, index)` ordered by `x` (as `total_cmp`), then `index`.
#[inline(always)]
pub fn f32_then_index(x: f32, index: u32) -> u64 {
    (u64::from(f32_key(x)) << 32) | u64::from(index)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_order_as_total_cmp_then_index() {
        let mut v: Vec<f32> = vec![
            0.0,
            -0.0,
            1.0,
            -1.0,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::from_bits(1),
            -f32::from_bits(1),
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
            3.5,
            -2.25,
        ];
        let mut rng = crate::xorshift::XorShift::new(5);
        for _ in 0..2000 {
            v.push(f32::from_bits((rng.next_f64() * 4_294_967_296.0) as u32));
        }
        for a in &v {
            for b in v.iter().step_by(7) {
                assert_eq!(f32_key(*a).cmp(&f32_key(*b)), a.total_cmp(b), "{a:e} {b:e}");
                for (i, j) in [(0, 1), (1, 0), (3, 3)] {
                    assert_eq!(
                        f32_then_index(*a, i).cmp(&f32_then_index(*b, j)),
                        a.total_cmp(b).then(i.cmp(&j)),
                    );
                }
            }
        }
    }
}
