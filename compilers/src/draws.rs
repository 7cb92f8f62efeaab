//! The uniform numbers of random dithering: one per voxel, a function of
//! the export's seed and the voxel's global index alone (no state), so
//! layers, rows, threads and shards draw the same numbers.
//!
//! Voxel `n` draws `u = (h >> 8) / 2²⁴ ∈ [0, 1)` (exact in `f32`) from the
//! 32-bit hash `h = mix32(key ^ lo)`, `lo` the low 32 bits of `n` and `key`
//! the top half of the SplitMix64 output of the seed at `n`'s high 32
//! bits ([`crate::dither::splitmix64`]: the whole seed matters). `mix32`
//! is Wellons' "lowbias32" (hash-prospector: two xorshift-multiply rounds,
//! a bijection with low avalanche bias). The hash has only 32-bit
//! multiplies, so a run's draws vectorise (SSE4.1's `pmulld`): a 64-bit
//! multiply has no vector form below AVX-512, and one SplitMix64 output a
//! voxel left the dithering loop one voxel at a time.

use crate::dither::splitmix64;

/// Wellons' "lowbias32" finaliser.
#[inline(always)]
fn mix32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

/// The key of the voxels whose global index has high 32 bits `hi`.
#[inline]
fn key(seed: u64, hi: u32) -> u32 {
    (splitmix64(seed, u64::from(hi)) >> 32) as u32
}

/// `u ∈ [0, 1)` from a hash's top 24 bits.
#[inline(always)]
fn unit(h: u32) -> f32 {
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// The number voxel `index` draws.
#[inline]
pub fn draw(seed: u64, index: u64) -> f32 {
    unit(mix32(key(seed, (index >> 32) as u32) ^ index as u32))
}

/// The number of voxel `i` of a piece (see [`pieces`]) drawing with `key`
/// from low index `low` on.
#[inline(always)]
pub(crate) fn nth(key: u32, low: u32, i: usize) -> f32 {
    unit(mix32(key ^ low.wrapping_add(i as u32)))
}

/// The voxels `first..first + n` in pieces that share their index's high
/// 32 bits: `(offset, key, low bits of the piece's first index, length)`.
/// One piece but where a run crosses a multiple of 2³² voxels.
pub(crate) fn pieces(
    seed: u64,
    first: u64,
    n: usize,
) -> impl Iterator<Item = (usize, u32, u32, usize)> {
    let mut done = 0usize;
    std::iter::from_fn(move || {
        if done >= n {
            return None;
        }
        let at = first + done as u64;
        let room = (1u64 << 32) - (at & 0xffff_ffff);
        let len = (n - done).min(usize::try_from(room).unwrap_or(usize::MAX));
        let piece = (done, key(seed, (at >> 32) as u32), at as u32, len);
        done += len;
        Some(piece)
    })
}

/// Calls `f(i, u)` for voxels `first + i`, `i < n`, with their numbers.
#[inline(always)]
pub(crate) fn each(seed: u64, first: u64, n: usize, mut f: impl FnMut(usize, f32)) {
    for (at, key, lo, len) in pieces(seed, first, n) {
        for i in 0..len {
            f(at + i, nth(key, lo, i));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lowbias32_matches_its_definition() {
        // Its two rounds worked by hand (Python integers masked to 32 bits).
        assert_eq!(mix32(0), 0);
        assert_eq!(mix32(1), 0x6889_90c0);
        assert_eq!(mix32(0xdead_beef), 0xe628_c683);
    }

    #[test]
    fn runs_across_a_multiple_of_two_to_the_32_draw_as_voxels_alone() {
        let first = (3u64 << 32) - 5;
        let mut got = Vec::new();
        each(42, first, 12, |i, u| got.push((i, u)));
        assert_eq!(got.len(), 12);
        for (i, u) in got {
            assert_eq!(u.to_bits(), draw(42, first + i as u64).to_bits(), "{i}");
        }
        let p: Vec<_> = pieces(42, first, 12).map(|p| (p.0, p.3)).collect();
        assert_eq!(p, [(0, 5), (5, 7)]);
    }

    #[test]
    fn draws_are_uniform_and_neighbours_independent() {
        // 64 buckets of a million consecutive voxels: chi-square with 63
        // degrees of freedom stays far below 150 (p < 10⁻⁸ beyond), and
        // pairs of neighbours fall in each quarter-square a quarter of
        // the time.
        let n = 1 << 20;
        let mut buckets = [0u32; 64];
        let mut pairs = [0u32; 4];
        let mut last = 0.0f32;
        each(7, 5_000_000_000, n, |i, u| {
            assert!((0.0..1.0).contains(&u));
            buckets[(u * 64.0) as usize] += 1;
            if i > 0 {
                pairs[usize::from(last < 0.5) * 2 + usize::from(u < 0.5)] += 1;
            }
            last = u;
        });
        let e = n as f64 / 64.0;
        let chi: f64 = buckets.iter().map(|&b| (b as f64 - e).powi(2) / e).sum();
        assert!(chi < 150.0, "chi-square {chi}");
        for p in pairs {
            assert!(
                (p as f64 / (n - 1) as f64 - 0.25).abs() < 0.003,
                "{pairs:?}"
            );
        }
        // Other seeds draw other numbers.
        assert_ne!(draw(7, 123).to_bits(), draw(8, 123).to_bits());
        assert_ne!(draw(7, 123).to_bits(), draw(7 | 1 << 40, 123).to_bits());
    }
}
