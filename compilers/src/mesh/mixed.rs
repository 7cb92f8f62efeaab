//! Which cubes of a row can hold surface: those whose eight corner labels
//! are not all one. The contourer asks this of every cube of every layer,
//! so it is the one per-voxel pass of contouring (solid and empty runs are
//! most of a grid).
//!
//! Branch-free and vectorisable: per chunk of 64 cubes, one pass computes
//! each cube's XOR-mix of its corners into a byte (0 or 1), and the bytes
//! are packed eight at a time into a bit mask with one multiplication
//! (`bytes · 0x0102040810204080 >> 56` gathers the low bit of each byte).
//! A chunk with no mixed cube costs about one instruction a cube, where
//! setting bits one shift at a time costs a compare, a shift and an OR per
//! cube.

/// Cubes per chunk (bits of the mask).
const CHUNK: usize = 64;

/// Rows `j` and `j + 1` of two planes' arrays of `len` items a row: the
/// four rows around row `j` of cubes.
pub(super) fn around<'a, T>(lo: &'a [T], hi: &'a [T], j: usize, len: usize) -> [&'a [T]; 4] {
    let row = |p: &'a [T], y: usize| &p[y * len..(y + 1) * len];
    [row(lo, j), row(lo, j + 1), row(hi, j), row(hi, j + 1)]
}

/// Cubes `i` of a row whose eight corners (columns `i` and `i + 1` of the
/// four label rows `a`, `b`, `c`, `d` around it) are not all one label,
/// ascending.
pub(super) fn mixed_cubes([a, b, c, d]: [&[u16]; 4]) -> impl Iterator<Item = usize> + '_ {
    let cubes = a.len().saturating_sub(1);
    (0..cubes).step_by(CHUNK).flat_map(move |i0| {
        let n = CHUNK.min(cubes - i0);
        let mut bits = chunk_mask([
            &a[i0..i0 + n + 1],
            &b[i0..i0 + n + 1],
            &c[i0..i0 + n + 1],
            &d[i0..i0 + n + 1],
        ]);
        std::iter::from_fn(move || {
            (bits != 0).then(|| {
                let t = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                i0 + t
            })
        })
    })
}

/// [`mixed_cubes`] from one label's rows as bits (bit `x % 64` of word
/// `x / 64` set where voxel `x`'s label is not 0; bits past the row's
/// `nx` voxels clear), appended to `out`: the same cubes, 64 at a time
/// with a few word operations, where the labels cost about one
/// instruction a cube. A plain loop into the caller's list: as an
/// iterator (`flat_map` of `from_fn`) each cube was a push with its own
/// capacity check and the iterator's state carried between them.
pub(super) fn push_mixed_from_bits([a, b, c, d]: [&[u64]; 4], nx: usize, out: &mut Vec<usize>) {
    let cubes = nx.saturating_sub(1);
    let words = a.len();
    // (The four rows have one length: no bounds checks below.)
    let (b, c, d) = (&b[..words], &c[..words], &d[..words]);
    let col = |w: usize| (a[w] ^ b[w]) | (a[w] ^ c[w]) | (a[w] ^ d[w]);
    // Each word's column mix once, carried to the word before it.
    let mut here = if words > 0 { col(0) } else { 0 };
    for w in 0..words {
        // Cube t of the word: columns t and t + 1 (bit 0 of the next word).
        let (next_col, next_a) = if w + 1 < words {
            (col(w + 1), a[w + 1])
        } else {
            (0, 0)
        };
        let right = (here >> 1) | (next_col << 63);
        let step = a[w] ^ ((a[w] >> 1) | (next_a << 63));
        let base = 64 * w;
        let mut bits = here | right | step;
        here = next_col;
        if base + 64 > cubes {
            bits &= (1u64 << cubes.saturating_sub(base)) - 1;
        }
        if bits == 0 {
            continue;
        }
        out.reserve(bits.count_ones() as usize);
        while bits != 0 {
            out.push(base + bits.trailing_zeros() as usize);
            bits &= bits - 1;
        }
    }
}

/// Bit `t` set when cube `t` of these `n + 1`-long rows (`n ≤ 64`) is mixed.
#[inline]
fn chunk_mask([a, b, c, d]: [&[u16]; 4]) -> u64 {
    let n = a.len() - 1;
    // Per column: does any of the four rows differ from row a?
    let mut col = [0u16; CHUNK + 1];
    for ((((o, a), b), c), d) in col.iter_mut().zip(a).zip(b).zip(c).zip(d) {
        *o = (a ^ b) | (a ^ c) | (a ^ d);
    }
    // Row a's label changes from column t to t + 1.
    let mut step = [0u16; CHUNK];
    for ((o, l), r) in step.iter_mut().zip(a).zip(&a[1..]) {
        *o = l ^ r;
    }
    let mut mixed = [0u8; CHUNK];
    for (((o, l), r), s) in mixed.iter_mut().zip(&col).zip(&col[1..]).zip(&step) {
        *o = u8::from((l | r | s) != 0);
    }
    // Columns past the row's end are zero in `col` and `step`, but the
    // last cube's right column is `col[n]`: clear the bits beyond n.
    let mut bits = 0u64;
    for (g, bytes) in mixed.as_chunks::<8>().0.iter().enumerate() {
        let word = u64::from_le_bytes(*bytes);
        bits |= (word.wrapping_mul(0x0102_0408_1020_4080) >> 56) << (8 * g);
    }
    if n < CHUNK {
        bits & ((1u64 << n) - 1)
    } else {
        bits
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every cube checked corner by corner.
    fn naive(rows: [&[u16]; 4]) -> Vec<usize> {
        let cubes = rows[0].len().saturating_sub(1);
        (0..cubes)
            .filter(|&i| {
                let l0 = rows[0][i];
                rows.iter().any(|r| r[i] != l0 || r[i + 1] != l0)
            })
            .collect()
    }

    /// Rows of labels as bits (bit x set where the label is not 0).
    fn as_bits(row: &[u16]) -> Vec<u64> {
        let mut w = vec![0u64; row.len().div_ceil(64)];
        for (x, l) in row.iter().enumerate() {
            w[x / 64] |= u64::from(*l != 0) << (x % 64);
        }
        w
    }

    /// Random rows of `len` labels below `labels`, changing at `density`,
    /// for each length and density tried.
    fn cases(seed: u64, labels: f64, mut check: impl FnMut([&[u16]; 4], usize, f64)) {
        let mut rng = volcad_core::bench::XorShift::new(seed);
        for len in [0, 1, 2, 8, 63, 64, 65, 66, 127, 128, 129, 300] {
            for density in [0.0, 0.01, 0.2, 1.0] {
                let mut row = || -> Vec<u16> {
                    let mut v = Vec::with_capacity(len);
                    let mut l = 1u16;
                    for _ in 0..len {
                        if rng.next_f64() < density {
                            l = (rng.next_f64() * labels) as u16;
                        }
                        v.push(l);
                    }
                    v
                };
                let (a, b, c, d) = (row(), row(), row(), row());
                check([&a[..], &b[..], &c[..], &d[..]], len, density);
            }
        }
    }

    #[test]
    fn finds_exactly_the_mixed_cubes() {
        cases(5, 4.0, |rows, len, density| {
            let found: Vec<usize> = mixed_cubes(rows).collect();
            assert_eq!(found, naive(rows), "{len} {density}");
        });
    }

    #[test]
    fn bits_find_the_cubes_labels_do() {
        cases(7, 2.0, |rows, len, density| {
            let bits = rows.map(as_bits);
            let words = [&bits[0][..], &bits[1][..], &bits[2][..], &bits[3][..]];
            let mut found = vec![usize::MAX];
            push_mixed_from_bits(words, len, &mut found);
            assert_eq!(found.remove(0), usize::MAX, "appends");
            assert_eq!(found, naive(rows), "{len} {density}");
        });
    }
}
