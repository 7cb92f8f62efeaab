//! One row of a plane labelled from its distances' signs alone
//! ([`super::segment::fixed_plane_into`]): `lab` where the distance is not
//! above zero (a NaN is not outside, as in `Classifier::plane_into`), 0
//! elsewhere, and the same as bits (bit `x % 64` of word `x / 64` set
//! where the label is not 0; bits past the row clear).
//!
//! Every voxel of a one-segment mesh export of a fixed mix passes here
//! once. On x86-64 eight
//! distances take two SSE2 compares (part of the architecture's baseline,
//! so no detection): their masks give the eight bits (`movemask`) and,
//! packed to 16 bits, the eight labels. Elsewhere the portable loops below
//! do the same, and a test compares the two.

/// Labels and bits of `dist` into `labels` (same length) and `bits`
/// (`dist.len().div_ceil(64)` words) for label `lab`, 0 or 1 (one
/// segment; the portable bits gather labels of 0 and 1).
pub(super) fn sign_row(labels: &mut [u16], bits: &mut [u64], dist: &[f32], lab: u16) {
    debug_assert!(lab <= 1, "label {lab}");
    debug_assert_eq!(labels.len(), dist.len());
    debug_assert_eq!(bits.len(), dist.len().div_ceil(64));
    #[cfg(target_arch = "x86_64")]
    {
        sign_row_sse2(labels, bits, dist, lab);
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        sign_row_portable(labels, bits, dist, lab);
    }
}

/// [`sign_row`] with SSE2: per eight distances, `d > 0` as two masks of
/// four lanes, the outside bits from `movemask`, and the labels as
/// `lab & !outside` on the masks packed to 16-bit lanes (`packs` keeps
/// −1 and 0). The compare is false for NaN, as `!(d > 0)` wants.
#[cfg(target_arch = "x86_64")]
fn sign_row_sse2(labels: &mut [u16], bits: &mut [u64], dist: &[f32], lab: u16) {
    use std::arch::x86_64::{
        __m128i, _mm_andnot_si128, _mm_castps_si128, _mm_cmpgt_ps, _mm_loadu_ps, _mm_movemask_ps,
        _mm_packs_epi32, _mm_set1_epi16, _mm_setzero_ps, _mm_storeu_si128,
    };
    // (Label 0 sets no bit.)
    let keep = if lab != 0 { u64::MAX } else { 0 };
    for ((word, ds), ls) in bits
        .iter_mut()
        .zip(dist.chunks(64))
        .zip(labels.chunks_mut(64))
    {
        // A whole word as fixed-size arrays: eight steps of constant
        // offsets, no bounds checks or iterator state between them.
        let (Ok(d), Ok(l)) = (
            <&[f32; 64]>::try_from(ds),
            <&mut [u16; 64]>::try_from(&mut *ls),
        ) else {
            // The row's last, short word.
            sign_row_portable(ls, std::slice::from_mut(word), ds, lab);
            continue;
        };
        let mut m = 0u64;
        for k in 0..8 {
            // SAFETY: SSE2 is in every x86-64 processor (the target's
            // baseline). The loads read floats 8k..8k + 8 of `d` and the
            // store writes labels 8k..8k + 8 of `l` (64 each, k < 8), in
            // their unaligned forms.
            let outside = unsafe {
                let zero = _mm_setzero_ps();
                let p = d.as_ptr().add(8 * k);
                let a = _mm_cmpgt_ps(_mm_loadu_ps(p), zero);
                let b = _mm_cmpgt_ps(_mm_loadu_ps(p.add(4)), zero);
                let packed = _mm_packs_epi32(_mm_castps_si128(a), _mm_castps_si128(b));
                let labels = _mm_andnot_si128(packed, _mm_set1_epi16(lab as i16));
                _mm_storeu_si128(l.as_mut_ptr().add(8 * k).cast::<__m128i>(), labels);
                _mm_movemask_ps(a) | _mm_movemask_ps(b) << 4
            };
            m |= u64::from(!outside as u8) << (8 * k);
        }
        *word = m & keep;
    }
}

/// [`sign_row`] without vector instructions: the labels eight at a time
/// as fixed-size arrays (vector compares where the target has them), then
/// the bits four labels a multiplication (also the SSE2 path's short last
/// word).
fn sign_row_portable(labels: &mut [u16], bits: &mut [u64], dist: &[f32], lab: u16) {
    sign_labels(labels, dist, lab);
    label_bits(labels, bits);
}

/// `lab` into `labels` where `dist` is not above zero (hence the negated
/// comparisons), 0 elsewhere.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn sign_labels(labels: &mut [u16], dist: &[f32], lab: u16) {
    let mut out = labels.chunks_exact_mut(8);
    let mut ds = dist.chunks_exact(8);
    for (o, d) in (&mut out).zip(&mut ds) {
        let m: [u16; 8] = std::array::from_fn(|k| u16::from(!(d[k] > 0.0)));
        for k in 0..8 {
            o[k] = m[k] * lab;
        }
    }
    for (o, d) in out.into_remainder().iter_mut().zip(ds.remainder()) {
        *o = u16::from(!(*d > 0.0)) * lab;
    }
}

/// Bit `x % 64` of word `x / 64` set where `labels[x]` is not 0 (labels 0
/// or 1): four labels a multiplication, read as one 64-bit word whose four
/// low bits of 16 the product gathers into bits 48..52 (the partial
/// products below bit 48 fall on distinct bits, so nothing carries in).
fn label_bits(labels: &[u16], bits: &mut [u64]) {
    const GATHER: u64 = 1 << 48 | 1 << 33 | 1 << 18 | 1 << 3;
    for (w, chunk) in bits.iter_mut().zip(labels.chunks(64)) {
        let (quads, rest) = chunk.as_chunks::<4>();
        let mut word = 0u64;
        for (q, l) in quads.iter().enumerate() {
            let v = u64::from(l[0])
                | u64::from(l[1]) << 16
                | u64::from(l[2]) << 32
                | u64::from(l[3]) << 48;
            word |= (v.wrapping_mul(GATHER) >> 48 & 0xF) << (4 * q);
        }
        for (k, l) in rest.iter().enumerate() {
            word |= u64::from(*l) << (4 * quads.len() + k);
        }
        *w = word;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows of every length up to 200 mixing the values the sign decides
    /// on (zeros of both signs, NaN, infinities, tiny and ordinary values):
    /// the row's labels and bits are the portable loops' and the
    /// definition's.
    #[test]
    fn rows_label_as_the_definition_says() {
        let special = [
            0.0f32,
            -0.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            1e-30,
            -1e-30,
            0.37,
            -2.5,
        ];
        let mut rng = volcad_core::bench::XorShift::new(17);
        for len in 0..200usize {
            for lab in [0u16, 1] {
                let dist: Vec<f32> = (0..len)
                    .map(|_| {
                        special[(rng.next_f64() * special.len() as f64) as usize % special.len()]
                    })
                    .collect();
                let words = len.div_ceil(64);
                let (mut labels, mut bits) = (vec![7u16; len], vec![u64::MAX; words]);
                sign_row(&mut labels, &mut bits, &dist, lab);
                let (mut l2, mut b2) = (vec![7u16; len], vec![u64::MAX; words]);
                sign_row_portable(&mut l2, &mut b2, &dist, lab);
                assert_eq!((&labels, &bits), (&l2, &b2), "{len} {lab}");
                for (x, d) in dist.iter().enumerate() {
                    #[allow(clippy::neg_cmp_op_on_partial_ord)]
                    let want = if !(*d > 0.0) { lab } else { 0 };
                    assert_eq!(labels[x], want, "{len} {x} {d}");
                    assert_eq!(
                        bits[x / 64] >> (x % 64) & 1,
                        u64::from(want != 0),
                        "{len} {x}"
                    );
                }
                if len % 64 != 0 {
                    assert_eq!(bits[words - 1] >> (len % 64), 0, "bits past the row");
                }
            }
        }
    }
}
