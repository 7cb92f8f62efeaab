//! Kerning pairs: the `kern` table where the font has one (the pairs
//! FreeType's `FT_Get_Kerning` reads, so pyvcad's spacing), else the pair
//! adjustments (GPOS lookup type 2) listed under the `kern` feature, which
//! is where newer fonts keep them.

use ttf_parser::GlyphId;
use ttf_parser::gpos::{PairAdjustment, PositioningSubtable};

/// Where a face's kerning pairs are.
pub(super) enum Kerning {
    None,
    Kern,
    /// Indices of the GPOS lookups of the `kern` feature.
    Gpos(Vec<u16>),
}

impl Kerning {
    pub(super) fn new(face: &ttf_parser::Face<'_>) -> Self {
        let has_kern = face
            .tables()
            .kern
            .is_some_and(|k| k.subtables.into_iter().any(|s| s.horizontal && !s.variable));
        if has_kern {
            Kerning::Kern
        } else {
            Self::gpos(face)
        }
    }

    /// The lookups of GPOS's `kern` feature, or `None`.
    fn gpos(face: &ttf_parser::Face<'_>) -> Self {
        let Some(gpos) = face.tables().gpos else {
            return Kerning::None;
        };
        let tag = ttf_parser::Tag::from_bytes(b"kern");
        let mut lookups: Vec<u16> = gpos
            .features
            .into_iter()
            .filter(|f| f.tag == tag)
            .flat_map(|f| f.lookup_indices.into_iter())
            .collect();
        lookups.sort_unstable();
        lookups.dedup();
        if lookups.is_empty() {
            Kerning::None
        } else {
            Kerning::Gpos(lookups)
        }
    }

    /// The advance adjustment between `left` and `right`, font units.
    pub(super) fn pair(&self, face: &ttf_parser::Face<'_>, left: GlyphId, right: GlyphId) -> i32 {
        match self {
            Kerning::None => 0,
            Kerning::Kern => face.tables().kern.map_or(0, |k| {
                k.subtables
                    .into_iter()
                    .filter(|s| s.horizontal && !s.variable && !s.has_cross_stream)
                    .filter_map(|s| s.glyphs_kerning(left, right))
                    .map(i32::from)
                    .sum()
            }),
            Kerning::Gpos(lookups) => face
                .tables()
                .gpos
                .map_or(0, |g| gpos_pair(&g, lookups, left, right)),
        }
    }
}

/// The first pair adjustment of the lookups that covers `(left, right)`:
/// the first glyph's advance change (a shaper applies one per pair).
fn gpos_pair(
    gpos: &ttf_parser::opentype_layout::LayoutTable<'_>,
    lookups: &[u16],
    left: GlyphId,
    right: GlyphId,
) -> i32 {
    for &li in lookups {
        let Some(lookup) = gpos.lookups.get(li) else {
            continue;
        };
        for sub in lookup.subtables.into_iter::<PositioningSubtable>() {
            let PositioningSubtable::Pair(pair) = sub else {
                continue;
            };
            let Some(cov) = pair.coverage().get(left) else {
                continue;
            };
            let found = match pair {
                PairAdjustment::Format1 { sets, .. } => sets.get(cov).and_then(|s| s.get(right)),
                PairAdjustment::Format2 {
                    classes, matrix, ..
                } => matrix.get((classes.0.get(left), classes.1.get(right))),
            };
            if let Some((first, _)) = found {
                return i32::from(first.x_advance);
            }
        }
    }
    0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// DejaVu Sans keeps its pairs in both tables: the GPOS reading must
    /// give the `kern` table's values.
    #[test]
    fn gpos_pairs_agree_with_the_kern_table() {
        let face = ttf_parser::Face::parse(super::super::font::BUNDLED, 0).unwrap();
        let gpos = Kerning::gpos(&face);
        assert!(matches!(gpos, Kerning::Gpos(_)));
        let kern = Kerning::new(&face);
        assert!(matches!(kern, Kerning::Kern));
        let g = |c: char| face.glyph_index(c).unwrap();
        let mut kerned = 0;
        for pair in ["AV", "To", "Yo", "LT", "HH", "ab", "P.", "AT", "r,"] {
            let mut cs = pair.chars();
            let (a, b) = (g(cs.next().unwrap()), g(cs.next().unwrap()));
            let (k, p) = (kern.pair(&face, a, b), gpos.pair(&face, a, b));
            assert_eq!(k, p, "{pair}");
            kerned += usize::from(k != 0);
        }
        assert!(kerned >= 5, "{kerned}");
        // FreeType's value for A, V (pyvcad 2.3.4: −0.6396 mm at 10 mm).
        assert_eq!(kern.pair(&face, g('A'), g('V')), -131);
    }
}
