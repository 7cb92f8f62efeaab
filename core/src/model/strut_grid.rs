//! The few struts of a unit-cell lattice that can be nearest, per sub-cell.
//!
//! A graph lattice's distance is the minimum over its cell's struts (12 for
//! FCC, 8 for BCC and more for the denser kinds), and a tiled lattice asks
//! it at every voxel. The cell is cut into `N³` sub-cells; each keeps the
//! struts that can be nearest to some point of it, and a query takes the
//! minimum over those only.
//!
//! Why it is exact (the argument of the mesh's candidate grid): let `c` be
//! the sub-cell's centre, `ρ` its half diagonal and `u` the distance from
//! `c` to the nearest strut axis. For `p` in the sub-cell, the nearest axis
//! `s*` of `p` has `d(p, s*) ≤ d(p, s_c) ≤ u + ρ`, so
//! `d(c, s*) ≤ d(p, s*) + ρ ≤ u + 2ρ`: the struts with `d(c, s) ≤ u + 2ρ`
//! include the nearest one of every point of the sub-cell. The bound is
//! widened by a relative 10⁻⁹ for rounding. Points outside the cell (a
//! lattice used without `Tile`) take every strut.

use glam::DVec3;

use super::shapes::Capsule;
use crate::fastmath::floor3;

/// Sub-cells per axis.
const N: usize = 8;

/// Per sub-cell strut lists over the cell box `[−h, h]`.
#[derive(Clone, Debug)]
pub struct StrutGrid {
    min: DVec3,
    inv_sub: DVec3,
    /// Sub-cell `i` lists `items[offsets[i]..offsets[i + 1]]`.
    offsets: Vec<u16>,
    items: Vec<u16>,
}

impl StrutGrid {
    /// The grid of a cell of half size `h` holding `struts`, or `None` when
    /// a short list would not pay (few struts) or the cell is degenerate.
    pub fn new(struts: &[Capsule], h: DVec3) -> Option<StrutGrid> {
        let box_ok = h.is_finite() && h.min_element() > 0.0;
        if struts.len() <= 4 || struts.len() > u16::MAX as usize || !box_ok {
            return None;
        }
        let sub = h * 2.0 / N as f64;
        let rho = 0.5 * sub.length();
        let min = -h;
        let mut offsets = Vec::with_capacity(N * N * N + 1);
        let mut items = Vec::new();
        offsets.push(0u16);
        for i in 0..N * N * N {
            let (x, y, z) = (i % N, i / N % N, i / (N * N));
            let c = min + (DVec3::new(x as f64, y as f64, z as f64) + 0.5) * sub;
            let d: Vec<f64> = struts.iter().map(|s| s.axis_dist2(c).sqrt()).collect();
            let u = d.iter().copied().fold(f64::INFINITY, f64::min);
            let reach = (u + 2.0 * rho) * (1.0 + 1e-9);
            items.extend(
                (0..struts.len())
                    .filter(|&k| d[k] <= reach)
                    .map(|k| k as u16),
            );
            offsets.push(u16::try_from(items.len()).ok()?);
        }
        Some(StrutGrid {
            min,
            inv_sub: DVec3::ONE / sub,
            offsets,
            items,
        })
    }

    /// The struts that can be nearest to `p`, or `None` outside the cell.
    #[inline]
    pub fn candidates(&self, p: DVec3) -> Option<&[u16]> {
        let g = floor3((p - self.min) * self.inv_sub);
        // Also false for NaN.
        let inside = |v: f64| v >= 0.0 && v < N as f64;
        if !(inside(g.x) && inside(g.y) && inside(g.z)) {
            return None;
        }
        let i = g.x as usize + N * (g.y as usize + N * g.z as usize);
        Some(&self.items[self.offsets[i] as usize..self.offsets[i + 1] as usize])
    }

    /// Mean list length: FCC 3.7 of 12 struts, cubic 3.1 of 12, Kelvin
    /// 8.5 of 36, octet 6.5 of 24.
    #[cfg(test)]
    pub fn mean_len(&self) -> f64 {
        self.items.len() as f64 / (N * N * N) as f64
    }
}

/// The struts that can be nearest to a point of the positive octant, when
/// the cell's struts are symmetric under the three axis reflections (every
/// built-in cell is): then `d(p) = d(|p|)` and the minimum over all struts
/// at `|p|` is the minimum over those that meet the closed octant `[0, ∞)³`,
/// at most half of them (BCC keeps one of four, FCC and Cubic three of
/// twelve). `None` when the set
/// is not symmetric (a custom cell), or too large to check.
///
/// Why: for `q ≥ 0` and any `x`, `|qᵢ − |xᵢ|| ≤ |qᵢ − xᵢ|`, so a strut `S`
/// is no nearer to `q` than its fold `|S|`; each piece of `|S|` is a piece
/// of a mirror image of `S` (a strut of the set) inside the octant, so of a
/// strut that meets the octant.
pub fn octant_struts(struts: &[Capsule]) -> Option<Vec<Capsule>> {
    if struts.is_empty() || struts.len() > 512 {
        return None;
    }
    let scale = struts
        .iter()
        .map(|s| s.a.abs().max((s.a + s.ab).abs()).max_element())
        .fold(0.0, f64::max);
    let tol = 1e-9 * scale.max(f64::MIN_POSITIVE);
    let near = |u: DVec3, v: DVec3| (u - v).abs().max_element() <= tol;
    let ends = |s: &Capsule| (s.a, s.a + s.ab);
    for axis in 0..3 {
        let mut flip = DVec3::ONE;
        flip[axis] = -1.0;
        let mirrored = struts.iter().all(|s| {
            let (a, b) = ends(s);
            let (a, b) = (a * flip, b * flip);
            struts.iter().any(|t| {
                let (c, d) = ends(t);
                (near(a, c) && near(b, d)) || (near(a, d) && near(b, c))
            })
        });
        if !mirrored {
            return None;
        }
    }
    // The part of a strut in the octant: the `t ∈ [0, 1]` with every
    // coordinate of `a + t·ab` at least `−tol`, or `None`.
    let span = |s: &Capsule| {
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for i in 0..3 {
            let (a, d) = (s.a[i] + tol, s.ab[i]);
            if d == 0.0 {
                if a < 0.0 {
                    return None;
                }
            } else if d > 0.0 {
                lo = lo.max(-a / d);
            } else {
                hi = hi.min(-a / d);
            }
        }
        (lo <= hi).then_some((lo, hi))
    };
    // Struts with a length inside; one that only touches the octant (BCC's
    // diagonals at the centre) is kept when no kept strut passes there.
    let mut few: Vec<Capsule> = Vec::new();
    let mut touching = Vec::new();
    for s in struts {
        match span(s) {
            Some((lo, hi)) if (hi - lo) * s.ab.length() > 8.0 * tol => few.push(*s),
            Some((lo, _)) => touching.push((s, s.a + s.ab * lo)),
            None => {}
        }
    }
    for (s, at) in touching {
        if !few.iter().any(|k| k.axis_dist2(at) <= 16.0 * tol * tol) {
            few.push(*s);
        }
    }
    Some(few)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::unit_cell_edges;
    use crate::node::LatticeType;

    #[test]
    fn short_lists_give_the_same_minimum() {
        let cell = DVec3::new(5.0, 4.0, 6.0);
        for kind in [
            LatticeType::BodyCenteredCubic,
            LatticeType::FaceCenteredCubic,
            LatticeType::Cubic,
            LatticeType::KelvinCell,
            LatticeType::Octet,
        ] {
            let struts: Vec<Capsule> = unit_cell_edges(kind, cell)
                .iter()
                .map(|(a, b)| Capsule::new(*a, *b, 0.3))
                .collect();
            let Some(g) = StrutGrid::new(&struts, cell * 0.5) else {
                assert!(struts.len() <= 4, "{kind:?}");
                continue;
            };
            assert!(
                g.mean_len() < struts.len() as f64 * 0.6,
                "{kind:?} {}",
                g.mean_len()
            );
            let mut rng = crate::xorshift::XorShift::new(0x1234_5678_9ABC_DEF1u64);
            let mut next = || rng.next_f64();
            for _ in 0..20_000 {
                // Inside the cell, and on sub-cell faces (multiples of 1/8).
                let f = DVec3::new(next(), next(), next());
                let f = if next() < 0.2 {
                    (f * 8.0).round() / 8.0
                } else {
                    f
                };
                let p = (f - 0.5) * cell;
                let all = struts
                    .iter()
                    .map(|s| s.axis_dist2(p))
                    .fold(f64::INFINITY, f64::min);
                let Some(list) = g.candidates(p) else {
                    assert!(f.max_element() >= 1.0, "{p}");
                    continue;
                };
                let short = list
                    .iter()
                    .map(|&k| struts[k as usize].axis_dist2(p))
                    .fold(f64::INFINITY, f64::min);
                assert_eq!(short.to_bits(), all.to_bits(), "{kind:?} at {p}");
            }
            assert!(g.candidates(cell).is_none());
            assert!(g.candidates(DVec3::NAN).is_none());
        }
    }

    #[test]
    fn octant_struts_give_the_same_minimum_at_the_folded_point() {
        let cell = DVec3::new(5.0, 4.0, 6.0);
        let mut rng = crate::xorshift::XorShift::new(0x0DDC_0FFE_E123_4567u64);
        for (kind, kept) in [
            (LatticeType::BodyCenteredCubic, 1),
            (LatticeType::FaceCenteredCubic, 3),
            (LatticeType::Cubic, 3),
            (LatticeType::KelvinCell, 0),
            (LatticeType::Octet, 0),
        ] {
            let struts: Vec<Capsule> = unit_cell_edges(kind, cell)
                .iter()
                .map(|(a, b)| Capsule::new(*a, *b, 0.3))
                .collect();
            let octant = octant_struts(&struts).expect("built-in cells are symmetric");
            if kept > 0 {
                assert_eq!(octant.len(), kept, "{kind:?}");
            }
            assert!(
                octant.len() * 2 <= struts.len(),
                "{kind:?} {}",
                octant.len()
            );
            for _ in 0..20_000 {
                // Inside the cell, on its mid planes, and outside it.
                let mut f = DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
                if rng.next_f64() < 0.2 {
                    f.x = 0.5;
                }
                let p = (f - 0.5) * cell * if rng.next_f64() < 0.2 { 3.0 } else { 1.0 };
                let all = struts
                    .iter()
                    .map(|s| s.axis_dist2(p))
                    .fold(f64::INFINITY, f64::min);
                let q = p.abs();
                let few = octant
                    .iter()
                    .map(|s| s.axis_dist2(q))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    (all.sqrt() - few.sqrt()).abs() < 1e-9,
                    "{kind:?} {p}: {all} {few}"
                );
            }
        }
    }

    #[test]
    fn a_lopsided_cell_is_not_folded() {
        let struts = [
            Capsule::new(DVec3::new(-1.0, -1.0, -1.0), DVec3::new(1.0, 1.0, 1.0), 0.1),
            Capsule::new(DVec3::new(-1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0), 0.1),
        ];
        assert!(octant_struts(&struts).is_none());
    }
}
