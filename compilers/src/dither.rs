//! One material per voxel from the sampled fractions, deterministically.
//!
//! Output codes: `0` = void, `s + 1` = the model's material slot `s`
//! (`Model::materials()[s]`). A voxel is void when it is outside (`d > 0`) or
//! its fractions sum to (almost) nothing; otherwise the fractions are
//! normalised by their total `T = Σ f_i`, so a voxel inside the part always
//! gets a material.
//!
//! Two schemes, both giving the same bytes whatever the thread count:
//!
//! * **Random** ([`choose_random`]): a counter-based generator keyed by the
//!   seed and the voxel's *global* index `n = (z·ny + y)·nx + x` (grid
//!   indices, `y` not flipped) draws `u ∈ [0, 1)` ([`crate::draws`]); the
//!   material is the first `i` with `u·T < Σ_{j ≤ i} f_j`. No state, so
//!   any voxel can be computed alone: layers, rows and threads are
//!   independent.
//! * **Error diffusion** ([`Diffuser`]): vector error diffusion in 3D. Each
//!   voxel picks the material with the largest target
//!   `t_i = f_i / T + e_i` (incoming error `e`, ties to the lowest slot), and
//!   its error `t − onehot(pick)` (a vector summing to zero) is shared by its
//!   neighbours with weights 1/4 to the same (x, y) in the next layer and
//!   3/4 within the layer as in Floyd–Steinberg (7/16 ahead in the row; 3/16,
//!   5/16, 1/16 behind, below and ahead in the next row), rows serpentine
//!   (even global rows left to right). Only neighbours that exist and are
//!   inside get a share, the weights renormalised over them, so error is not
//!   lost at the part's surface or a row's end, and material counts follow
//!   the fractions closely (error arriving from below into void is dropped).
//!
//!   Floyd–Steinberg is serial along its scan, so for parallelism and
//!   determinism the scan is cut at fixed places in *grid* coordinates, never
//!   at places that depend on threads: each layer is cut into strips of
//!   [`STRIP_ROWS`] rows (diffused in parallel; no error crosses a strip
//!   edge), and z error stays within blocks of [`BLOCK_LAYERS`] layers
//!   (`z % BLOCK_LAYERS == 0` starts a block), so a layer range `A..B` is
//!   reproduced exactly by starting the diffusion at `A − A % BLOCK_LAYERS`
//!   (at most 15 extra layers sampled, not written).

use rayon::prelude::*;

/// Rows per independently diffused strip of a layer.
pub const STRIP_ROWS: usize = 32;
/// Layers per block of z error diffusion (the z error is reset at
/// `z % BLOCK_LAYERS == 0`).
pub const BLOCK_LAYERS: usize = 16;
/// Share of a voxel's error carried to the next layer.
const W_Z: f32 = 0.25;
/// In-layer shares: Floyd–Steinberg's 7, 3, 5, 1 (/16) scaled by `1 − W_Z`.
const W_AHEAD: f32 = 0.75 * 7.0 / 16.0;
const W_NEXT_BEHIND: f32 = 0.75 * 3.0 / 16.0;
const W_NEXT_BELOW: f32 = 0.75 * 5.0 / 16.0;
const W_NEXT_AHEAD: f32 = 0.75 * 1.0 / 16.0;
/// Fraction totals at or below this are void (slice stacks and segment
/// labels alike).
pub(crate) const MIN_TOTAL: f32 = 1e-6;
/// Widening of fraction bounds before a decision is taken from them (a
/// random pick, a segment label): far above the `f32` rounding of sampled
/// fractions and of sums of at most 64 of them (`64 · 2⁻²⁴ ≈ 4·10⁻⁶`), far
/// below the fraction steps that matter.
pub(crate) const BOUND_MARGIN: f64 = 1e-5;

/// The Floyd–Steinberg neighbours of `x` on a serpentine row: the columns
/// ahead of and behind it in the row's direction (`forward`: rising x), and
/// which of the four error receivers (ahead in `row`; behind, below and
/// ahead in `below`) exist and are inside. A column off either end
/// (`usize::MAX` or `nx`) is not inside.
#[inline]
pub(crate) fn serpentine_neighbours(
    row: &[bool],
    below: Option<&[bool]>,
    x: usize,
    forward: bool,
) -> (usize, usize, [bool; 4]) {
    let (ahead, behind) = if forward {
        (x + 1, x.wrapping_sub(1))
    } else {
        (x.wrapping_sub(1), x + 1)
    };
    let at =
        |cells: Option<&[bool]>, i: usize| cells.and_then(|c| c.get(i)).copied().unwrap_or(false);
    let has = [
        at(Some(row), ahead),
        at(below, behind),
        at(below, x),
        at(below, ahead),
    ];
    (ahead, behind, has)
}

/// SplitMix64's increment (2⁶⁴ / φ).
const GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// The `index`-th output of the SplitMix64 stream started at `seed`:
/// `mix(seed + (index + 1)·γ)` with Stafford's "Mix13" finaliser.
#[inline]
pub fn splitmix64(seed: u64, index: u64) -> u64 {
    let mut z = seed.wrapping_add(index.wrapping_add(1).wrapping_mul(GAMMA));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Random choice for a run of consecutive voxels whose first voxel has global
/// index `first_index`; `dist` and `out` have one entry per voxel, `fracs`
/// `k` per voxel.
pub fn choose_random(
    seed: u64,
    first_index: u64,
    dist: &[f32],
    fracs: &[f32],
    k: usize,
    out: &mut [u8],
) {
    crate::draws::each(seed, first_index, out.len(), |v, r| {
        out[v] = if dist[v] > 0.0 {
            0
        } else {
            pick_random(&fracs[v * k..(v + 1) * k], r)
        };
    });
}

/// The code of an inside voxel with fractions `f` for the uniform number
/// `r ∈ [0, 1)`: the first `i` with `r·T < Σ_{j≤i} f_j`, 0 when `T` is
/// (almost) nothing.
#[inline]
pub(crate) fn pick_random(f: &[f32], r: f32) -> u8 {
    let k = f.len();
    if k == 1 {
        return u8::from(f[0] > MIN_TOTAL);
    }
    let total: f32 = f.iter().sum();
    if total.is_nan() || total <= MIN_TOTAL {
        return 0;
    }
    let u = r * total;
    // The first i with u < Σ_{j≤i} f_j is the number of running sums
    // ≤ u (they never decrease); counted without branches, since the
    // pick is unpredictable in a mix. A zero fraction is never picked.
    let mut acc = 0.0f32;
    let mut pick = 0usize;
    for fi in f {
        acc += fi;
        pick += usize::from(acc <= u);
    }
    if pick >= k {
        // Rounding left u at or above the total: the last material then.
        pick = f.iter().rposition(|fi| *fi > 0.0).unwrap_or(0);
    }
    pick as u8 + 1
}

/// 3D error diffusion over consecutive layers of an `nx × ny` grid with `k`
/// fractions per voxel. Holds the error carried to the next layer.
pub struct Diffuser {
    nx: usize,
    ny: usize,
    k: usize,
    /// z error per voxel of the layer just done (`k` per voxel).
    carry: Vec<f32>,
    /// The layer expected next (`None` before the first).
    next_z: Option<usize>,
}

impl Diffuser {
    /// A diffuser for layers of `nx × ny` voxels with `k` fractions each.
    pub fn new(nx: usize, ny: usize, k: usize) -> Self {
        let carry = if k > 1 {
            vec![0.0; nx * ny * k]
        } else {
            Vec::new()
        };
        Self {
            nx,
            ny,
            k,
            carry,
            next_z: None,
        }
    }

    /// The first layer to diffuse so that layer `z` comes out as in a full
    /// run (the start of its block).
    pub fn warmup_start(z: usize) -> usize {
        z - z % BLOCK_LAYERS
    }

    /// Bytes held per voxel of a layer.
    pub fn bytes_per_voxel(k: usize) -> usize {
        if k > 1 { 4 * k } else { 0 }
    }

    /// Dither layer `z` (`dist`: `nx·ny` values, `fracs`: `k` per voxel) into
    /// `out`. Layers must come in order, each block from its start.
    ///
    /// # Panics
    /// If a layer is skipped inside a block (the output would depend on where
    /// the run started).
    pub fn layer(&mut self, z: usize, dist: &[f32], fracs: &[f32], out: &mut [u8]) {
        let (nx, k) = (self.nx, self.k);
        assert_eq!(dist.len(), nx * self.ny, "layer size");
        if z.is_multiple_of(BLOCK_LAYERS) {
            self.carry.fill(0.0);
        } else {
            assert_eq!(
                self.next_z,
                Some(z),
                "error diffusion must run each block from its first layer"
            );
        }
        self.next_z = Some(z + 1);
        if k == 1 {
            // One material: every inside voxel is it, and no error arises.
            out.par_chunks_mut(nx)
                .zip(dist.par_chunks(nx))
                .zip(fracs.par_chunks(nx))
                .for_each(|((o, d), f)| {
                    for ((o, d), f) in o.iter_mut().zip(d).zip(f) {
                        *o = u8::from(*d <= 0.0 && *f > MIN_TOTAL);
                    }
                });
            return;
        }
        let strip = STRIP_ROWS * nx;
        let carry_on = z % BLOCK_LAYERS != BLOCK_LAYERS - 1;
        self.carry
            .par_chunks_mut(strip * k)
            .zip(out.par_chunks_mut(strip))
            .zip(dist.par_chunks(strip))
            .zip(fracs.par_chunks(strip * k))
            .enumerate()
            .for_each(|(s, (((carry, out), dist), fracs))| {
                let y0 = s * STRIP_ROWS;
                match k {
                    2 => diffuse_strip::<2>(y0, nx, k, carry_on, dist, fracs, carry, out),
                    3 => diffuse_strip::<3>(y0, nx, k, carry_on, dist, fracs, carry, out),
                    4 => diffuse_strip::<4>(y0, nx, k, carry_on, dist, fracs, carry, out),
                    _ => diffuse_strip::<0>(y0, nx, k, carry_on, dist, fracs, carry, out),
                }
            });
    }
}

/// Serial Floyd–Steinberg over one strip whose first row is global row `y0`;
/// `carry_on`: whether error may go to the next layer (not on a block's
/// last). `K` is the fraction count when known at compile time (loops
/// unroll), 0 to use `k`.
#[allow(clippy::too_many_arguments)]
fn diffuse_strip<const K: usize>(
    y0: usize,
    nx: usize,
    k: usize,
    carry_on: bool,
    dist: &[f32],
    fracs: &[f32],
    carry: &mut [f32],
    out: &mut [u8],
) {
    let k = if K == 0 { k } else { K };
    let rows = dist.len() / nx;
    let inside: Vec<bool> = (0..rows * nx)
        .map(|v| dist[v] <= 0.0 && fracs[v * k..(v + 1) * k].iter().sum::<f32>() > MIN_TOTAL)
        .collect();
    // Row error buffers with one padding cell at each end (index x + 1).
    let mut cur = vec![0.0f32; (nx + 2) * k];
    let mut next = vec![0.0f32; (nx + 2) * k];
    let mut target = vec![0.0f32; k];
    let w_z = if carry_on { W_Z } else { 0.0 };
    for r in 0..rows {
        let forward = (y0 + r).is_multiple_of(2);
        let next_row = (r + 1 < rows).then(|| &inside[(r + 1) * nx..(r + 2) * nx]);
        let row = &inside[r * nx..(r + 1) * nx];
        for step in 0..nx {
            let x = if forward { step } else { nx - 1 - step };
            let v = r * nx + x;
            let c = &mut carry[v * k..(v + 1) * k];
            if !row[x] {
                out[v] = 0;
                c.fill(0.0);
                continue;
            }
            let f = &fracs[v * k..(v + 1) * k];
            let xi = x + 1;
            // A single material with no incoming error: its error is zero,
            // nothing to share (most voxels of multi-material parts).
            let incoming = &cur[xi * k..(xi + 1) * k];
            if c.iter().chain(incoming).all(|e| *e == 0.0) {
                let mut nonzero = f.iter().enumerate().filter(|(_, fi)| **fi > 0.0);
                if let (Some((i, _)), None) = (nonzero.next(), nonzero.next()) {
                    out[v] = i as u8 + 1;
                    continue;
                }
            }
            let inv = 1.0 / f.iter().sum::<f32>();
            for i in 0..k {
                target[i] = f[i] * inv + incoming[i] + c[i];
            }
            // Branch-free argmax (the pick is unpredictable in a mix).
            let mut best = 0;
            for i in 1..k {
                best = if target[i] > target[best] { i } else { best };
            }
            out[v] = best as u8 + 1;
            for (i, t) in target.iter_mut().enumerate() {
                *t -= f32::from(u8::from(i == best));
            }
            // Neighbours that exist and are inside share the error in
            // proportion to their weights, so no error is lost inside the part.
            let (ahead, behind, has) = serpentine_neighbours(row, next_row, x, forward);
            let w = if has == [true; 4] && carry_on {
                [W_AHEAD, W_NEXT_BEHIND, W_NEXT_BELOW, W_NEXT_AHEAD, W_Z]
            } else {
                let mut w = [0.0, 0.0, 0.0, 0.0, w_z];
                for (wi, (h, full)) in w.iter_mut().zip(has.iter().zip([
                    W_AHEAD,
                    W_NEXT_BEHIND,
                    W_NEXT_BELOW,
                    W_NEXT_AHEAD,
                ])) {
                    if *h {
                        *wi = full;
                    }
                }
                let sum: f32 = w.iter().sum();
                if sum == 0.0 {
                    c.fill(0.0);
                    continue;
                }
                w.map(|wi| wi / sum)
            };
            // Padded indices: out-of-row neighbours have weight 0 and land in padding.
            let (ai, bi) = (
                ahead.wrapping_add(1).min(nx + 1),
                behind.wrapping_add(1).min(nx + 1),
            );
            for i in 0..k {
                let e = target[i];
                c[i] = w[4] * e;
                cur[ai * k + i] += w[0] * e;
                next[bi * k + i] += w[1] * e;
                next[xi * k + i] += w[2] * e;
                next[ai * k + i] += w[3] * e;
            }
        }
        std::mem::swap(&mut cur, &mut next);
        next.fill(0.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A layer where every voxel is inside with fractions (a, 1 − a).
    fn uniform(nx: usize, ny: usize, a: f32) -> (Vec<f32>, Vec<f32>) {
        let dist = vec![-1.0; nx * ny];
        let fracs = (0..nx * ny).flat_map(|_| [a, 1.0 - a]).collect();
        (dist, fracs)
    }

    fn share_of_first(out: &[u8]) -> f64 {
        out.iter().filter(|c| **c == 1).count() as f64 / out.len() as f64
    }

    #[test]
    fn splitmix_matches_reference_stream() {
        // SplitMix64 seeded with 1234567: first outputs (Vigna's reference).
        assert_eq!(splitmix64(1_234_567, 0), 6_457_827_717_110_365_317);
        assert_eq!(splitmix64(1_234_567, 1), 3_203_168_211_198_807_973);
    }

    #[test]
    fn random_and_diffusion_keep_the_fractions() {
        let (nx, ny) = (200, 100);
        for a in [0.1f32, 0.3, 0.5, 0.8] {
            let (dist, fracs) = uniform(nx, ny, a);
            let mut out = vec![0u8; nx * ny];
            choose_random(7, 0, &dist, &fracs, 2, &mut out);
            assert!((share_of_first(&out) - a as f64).abs() < 0.01, "random {a}");
            // Error goes partly to the next layer: measure over a block.
            let mut d = Diffuser::new(nx, ny, 2);
            let mut all = Vec::new();
            for z in 0..BLOCK_LAYERS {
                d.layer(z, &dist, &fracs, &mut out);
                all.extend_from_slice(&out);
            }
            assert!(
                (share_of_first(&all) - a as f64).abs() < 0.001,
                "diffusion {a}: {}",
                share_of_first(&all)
            );
        }
    }

    #[test]
    fn random_pick_is_the_first_running_sum_above_u() {
        // Reference: the definition, with branches.
        let k = 4;
        let n = 20_000;
        let mut fracs = Vec::with_capacity(n * k);
        for v in 0..n as u64 {
            for i in 0..k as u64 {
                let h = splitmix64(99, v * 8 + i);
                // A quarter of the fractions are exactly zero.
                fracs.push(if h.is_multiple_of(4) {
                    0.0
                } else {
                    (h >> 40) as f32 / 16_777_216.0
                });
            }
        }
        let dist = vec![-1.0; n];
        let mut out = vec![0u8; n];
        choose_random(5, 1000, &dist, &fracs, k, &mut out);
        for v in 0..n {
            let f = &fracs[v * k..(v + 1) * k];
            let total: f32 = f.iter().sum();
            if total <= MIN_TOTAL {
                assert_eq!(out[v], 0);
                continue;
            }
            let u = crate::draws::draw(5, 1000 + v as u64) * total;
            let mut acc = 0.0;
            let mut want = f.iter().rposition(|x| *x > 0.0).unwrap();
            for (i, fi) in f.iter().enumerate() {
                acc += fi;
                if u < acc {
                    want = i;
                    break;
                }
            }
            assert_eq!(out[v] as usize, want + 1, "voxel {v}: {f:?}");
            assert!(f[want] > 0.0);
        }
    }

    #[test]
    fn void_and_zero_totals_stay_void() {
        let dist = vec![1.0, -1.0, -1.0, -1.0];
        let fracs = vec![1.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.25, 0.25];
        let mut out = vec![9u8; 4];
        choose_random(1, 0, &dist, &fracs, 2, &mut out);
        assert_eq!(&out[..3], &[0, 0, 2]);
        assert!(out[3] == 1 || out[3] == 2);
        let mut d = Diffuser::new(4, 1, 2);
        d.layer(0, &dist, &fracs, &mut out);
        assert_eq!(&out[..3], &[0, 0, 2]);
    }

    #[test]
    fn diffusion_alternates_between_layers() {
        // 50/50: the z error makes the next layer the complement of this one.
        let (nx, ny) = (16, 16);
        let (dist, fracs) = uniform(nx, ny, 0.5);
        let mut d = Diffuser::new(nx, ny, 2);
        let (mut a, mut b) = (vec![0u8; nx * ny], vec![0u8; nx * ny]);
        d.layer(0, &dist, &fracs, &mut a);
        d.layer(1, &dist, &fracs, &mut b);
        let same = a.iter().zip(&b).filter(|(x, y)| x == y).count();
        assert!(same < nx * ny / 2, "layers should differ, {same} equal");
    }

    #[test]
    #[should_panic(expected = "each block from its first layer")]
    fn diffusion_refuses_to_start_mid_block() {
        let (dist, fracs) = uniform(4, 4, 0.5);
        let mut out = vec![0u8; 16];
        Diffuser::new(4, 4, 2).layer(3, &dist, &fracs, &mut out);
    }
}
