//! Floyd–Steinberg error diffusion of one layer's wanted colours onto the
//! resins, in OKLab plus opacity.
//!
//! Each voxel is a point `[L, a, b, opacity]`; each resin too. Inside
//! voxels are visited row by row, even rows left to right and odd rows
//! right to left (serpentine, so the error does not drift one way); a
//! voxel takes the resin nearest (Euclidean) to its wanted colour plus the
//! error it received, and passes the difference on with Floyd and
//! Steinberg's weights (7/16 ahead in its row; 3/16, 5/16, 1/16 behind,
//! below and ahead in the next row). Only neighbours inside the part take
//! a share, the weights renormalised over them, so no error leaks into
//! void and the mean over a region follows the wanted mean up to the error
//! left at the region's edge. Layers are independent: a layer's result
//! depends on its own voxels only, never on threads or on other layers.
//!
//! Where the wanted colours do not change from layer to layer, plain error
//! diffusion settles into the same pattern on every layer, and a thick part
//! shows it as columns of one resin through its thickness (stripes on its
//! sides). So the choice is made on the wanted colour plus the error plus
//! a seeded offset of its lightness of up to [`JITTER`], keyed by the
//! voxel's global index (threshold modulation); the error passed on is
//! still measured from the unshifted sum, so means are kept. Lightness
//! alone: an offset of hue would put stray coloured voxels in a region
//! whose colour is one resin's.

/// Channels of a wanted colour: OKLab L, a, b and opacity.
pub const CHANNELS: usize = 4;

/// A wanted colour or a resin: `[L, a, b, opacity]`.
pub type Ink = [f32; CHANNELS];

/// Largest seeded offset of a voxel's lightness before its resin is chosen
/// (OKLab, lightness 0 to 1): a fraction of the distance between
/// neighbouring resins, enough to break layer-to-layer repeats, small
/// against the error diffusion's own swings.
pub const JITTER: f32 = 0.06;

/// Floyd–Steinberg's weights: ahead, next row behind, below, ahead.
const FS: [f32; 4] = [7.0 / 16.0, 3.0 / 16.0, 5.0 / 16.0, 1.0 / 16.0];

/// The index of the resin nearest to `t` (ties to the lowest index).
#[inline]
pub fn nearest(resins: &[Ink], t: &Ink) -> usize {
    let mut best = (f32::INFINITY, 0);
    for (i, r) in resins.iter().enumerate() {
        let d: f32 = r.iter().zip(t).map(|(a, b)| (a - b) * (a - b)).sum();
        if d < best.0 {
            best = (d, i);
        }
    }
    best.1
}

/// Diffuse one `nx`-wide layer: `wanted` has one colour per voxel (read
/// only where `inside`); `out` gets `resin + 1` inside and 0 outside.
/// `jitter`: the seed and the layer's first global voxel index of the
/// seeded offsets (`None`: none).
pub fn diffuse_layer(
    nx: usize,
    wanted: &[Ink],
    inside: &[bool],
    resins: &[Ink],
    jitter: Option<(u64, u64)>,
    out: &mut [u8],
) {
    let rows = inside.len() / nx.max(1);
    // Error rows with one padding cell at each end (index x + 1).
    let mut cur = vec![[0.0f32; CHANNELS]; nx + 2];
    let mut next = vec![[0.0f32; CHANNELS]; nx + 2];
    for y in 0..rows {
        let row = &inside[y * nx..(y + 1) * nx];
        let below = (y + 1 < rows).then(|| &inside[(y + 1) * nx..(y + 2) * nx]);
        let forward = y % 2 == 0;
        for step in 0..nx {
            let x = if forward { step } else { nx - 1 - step };
            let v = y * nx + x;
            if !row[x] {
                out[v] = 0;
                continue;
            }
            let mut t = wanted[v];
            for (c, e) in t.iter_mut().zip(cur[x + 1]) {
                *c += e;
            }
            let pick = match jitter {
                Some((seed, first)) => {
                    let u = crate::draws::draw(seed, first + v as u64);
                    let mut s = t;
                    s[0] += JITTER * (2.0 * u - 1.0);
                    nearest(resins, &s)
                }
                None => nearest(resins, &t),
            };
            // `resins` has at most 255 entries (checked where it is built).
            out[v] = (pick + 1) as u8;
            let err: Ink = [0, 1, 2, 3].map(|c| t[c] - resins[pick][c]);
            let (ahead, behind, has) = crate::dither::serpentine_neighbours(row, below, x, forward);
            let total: f32 = FS.iter().zip(has).filter(|(_, h)| *h).map(|(w, _)| w).sum();
            if total == 0.0 {
                continue;
            }
            let w = [0, 1, 2, 3].map(|i| if has[i] { FS[i] / total } else { 0.0 });
            // Padded indices; a missing neighbour has weight 0.
            let (ai, bi) = (ahead.wrapping_add(1), behind.wrapping_add(1));
            let (ai, bi) = (ai.min(nx + 1), bi.min(nx + 1));
            for c in 0..CHANNELS {
                cur[ai][c] += w[0] * err[c];
                next[bi][c] += w[1] * err[c];
                next[x + 1][c] += w[2] * err[c];
                next[ai][c] += w[3] * err[c];
            }
        }
        std::mem::swap(&mut cur, &mut next);
        next.fill([0.0; CHANNELS]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const BLACK: Ink = [0.0, 0.0, 0.0, 1.0];
    const WHITE: Ink = [1.0, 0.0, 0.0, 1.0];
    const CLEAR: Ink = [1.0, 0.0, 0.0, 0.0];

    #[test]
    fn grey_averages_to_grey_and_outside_takes_nothing() {
        let (nx, ny) = (64, 64);
        // A disc inside a square.
        let inside: Vec<bool> = (0..nx * ny)
            .map(|v| {
                let (x, y) = ((v % nx) as f32 - 31.5, (v / nx) as f32 - 31.5);
                x.hypot(y) < 28.0
            })
            .collect();
        let wanted = vec![[0.3, 0.0, 0.0, 1.0]; nx * ny];
        let mut out = vec![9u8; nx * ny];
        diffuse_layer(nx, &wanted, &inside, &[BLACK, WHITE, CLEAR], None, &mut out);
        let n_in = inside.iter().filter(|i| **i).count();
        let white = out.iter().filter(|c| **c == 2).count();
        assert!(out.iter().zip(&inside).all(|(c, i)| (*c == 0) != *i));
        assert!(!out.contains(&3), "an opaque grey never takes clear");
        let share = white as f64 / n_in as f64;
        assert!((share - 0.3).abs() < 0.005, "{share}");
    }

    #[test]
    fn half_opacity_is_half_clear() {
        let (nx, ny) = (50, 40);
        let inside = vec![true; nx * ny];
        let wanted = vec![[1.0, 0.0, 0.0, 0.5]; nx * ny];
        let mut out = vec![0u8; nx * ny];
        diffuse_layer(nx, &wanted, &inside, &[BLACK, WHITE, CLEAR], None, &mut out);
        let clear = out.iter().filter(|c| **c == 3).count();
        assert!(out.iter().all(|c| *c == 2 || *c == 3));
        assert!((clear as f64 / (nx * ny) as f64 - 0.5).abs() < 0.01);
    }

    #[test]
    fn seeded_offsets_vary_the_pattern_by_layer_and_keep_the_mean() {
        // The same grey on two layers: plain diffusion repeats its pattern
        // exactly (columns of one resin through a thick part); with the
        // seeded offsets the layers differ and the share stays.
        let (nx, ny) = (64, 64);
        let inside = vec![true; nx * ny];
        let wanted = vec![[0.3, 0.0, 0.0, 1.0]; nx * ny];
        let inks = [BLACK, WHITE, CLEAR];
        let layer = |jitter| {
            let mut out = vec![0u8; nx * ny];
            diffuse_layer(nx, &wanted, &inside, &inks, jitter, &mut out);
            out
        };
        assert_eq!(layer(None), layer(None));
        let (a, b) = (layer(Some((7, 0))), layer(Some((7, (nx * ny) as u64))));
        let same = a.iter().zip(&b).filter(|(x, y)| x == y).count();
        assert!(
            same < nx * ny * 3 / 4,
            "{same} of {} voxels repeat",
            nx * ny
        );
        for out in [&a, &b] {
            let share = out.iter().filter(|c| **c == 2).count() as f64 / (nx * ny) as f64;
            assert!((share - 0.3).abs() < 0.01, "{share}");
        }
        assert_eq!(a, layer(Some((7, 0))), "the same seed and layer repeat");
    }
}
