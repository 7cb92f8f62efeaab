//! Scalar -> fractions (design by intent): `Convert(child, from,
//! fractions([a, b]), table)` gives the child the mix of two materials
//! whose measured value of `from` is the target, by inverting a mix table.
//!
//! A row is `(share, value)`: the share of the second material (0 = pure
//! first material, 1 = pure second) and the value measured for that mix
//! (a Shore hardness, a modulus). The rows rise in share and the value
//! must be strictly monotonic along them (rising or falling), so each
//! value within the table has exactly one mix: the inverse is the same
//! piecewise-linear table read the other way. Targets outside the values
//! are clamped to the end rows and counted, as a conversion table's are.
//!
//! Three or more materials: one number cannot pick a point of the
//! fractions' simplex (two or more degrees of freedom; every mix on a
//! curve through it measures the same value), so the table names the
//! path: each row is a full fractions row and its measured value
//! (`[f₁, …, fₙ, value]`), the mix runs straight from row to row, and the
//! value must be strictly monotonic along the rows. A value is then one
//! place on the path, found as for two materials (the inverse table maps
//! the value to the position along the rows, row i at i).

use super::convert::{Table, check_pairs, check_rising, csv_cells, csv_rows};
use crate::interval::Interval;

/// How far a row's fractions may add up away from 1 (rounding of typed
/// decimals such as 0.3, 0.3, 0.4).
const SUM_TOLERANCE: f64 = 1e-9;

/// A mix table, inverted for lookups by value.
#[derive(Clone, Debug, PartialEq)]
pub struct MixTable {
    /// Two materials: value -> share of the second. More: value ->
    /// position along `rows`.
    inverse: Table,
    /// Each row's fractions (three or more materials); empty for two.
    rows: Vec<Vec<f64>>,
}

/// The direction of strictly monotonic `values` (true: rising), or the
/// message naming the rows that break it.
fn direction(values: &[f64], what: &str) -> Result<bool, String> {
    let rising = values[1] > values[0];
    let breaks = |a: f64, b: f64| if rising { b <= a } else { b >= a };
    if let Some(i) = values.windows(2).position(|w| breaks(w[0], w[1])) {
        let way = if rising { "rise" } else { "fall" };
        return Err(format!(
            "{what}: rows {} and {} (values {} then {}) break the order: the values must {way} strictly along the rows (rows 1 and 2 set the direction) so that each value has one mix; a table whose value turns back cannot be inverted: keep the monotonic part of the table",
            i + 1,
            i + 2,
            values[i],
            values[i + 1]
        ));
    }
    Ok(rising)
}

/// The inverse of `(position, value)` rows whose values are monotonic.
fn inverse(rows: &[(f64, f64)], rising: bool, what: &str) -> Result<Table, String> {
    let mut pairs: Vec<(f64, f64)> = rows.iter().map(|(s, v)| (*v, *s)).collect();
    if !rising {
        pairs.reverse();
    }
    Table::new(&pairs, what)
}

impl MixTable {
    /// A table of `(share of the second material, value)` rows; `what`
    /// names it in errors.
    pub(crate) fn new(rows: &[(f64, f64)], what: &str) -> Result<MixTable, String> {
        check_pairs(rows, what, "a mix table", "(share, value)")?;
        for (i, (s, _)) in rows.iter().enumerate() {
            if !(0.0..=1.0).contains(s) {
                return Err(format!(
                    "{what}: row {} has share {s}; the first column is the second material's share, 0 (pure first material) to 1 (pure second)",
                    i + 1
                ));
            }
        }
        check_rising(rows, what, "share")?;
        let values: Vec<f64> = rows.iter().map(|r| r.1).collect();
        let rising = direction(&values, what)?;
        Ok(MixTable {
            inverse: inverse(rows, rising, what)?,
            rows: Vec::new(),
        })
    }

    /// A path through the fractions of `n` ≥ 3 materials: rows of `n`
    /// fractions (each ≥ 0, adding to 1) and the value measured for them.
    pub(crate) fn path(rows: &[Vec<f64>], n: usize, what: &str) -> Result<MixTable, String> {
        if rows.len() < 2 {
            return Err(format!(
                "{what} has {} rows; a mix table needs at least 2 rows of {n} fractions and a value",
                rows.len()
            ));
        }
        for (i, r) in rows.iter().enumerate() {
            let row = i + 1;
            if r.len() != n + 1 {
                return Err(format!(
                    "{what}: row {row} has {} numbers; each row is the {n} materials' fractions, then the value ({} numbers)",
                    r.len(),
                    n + 1
                ));
            }
            if let Some(v) = r.iter().find(|v| !v.is_finite()) {
                return Err(format!(
                    "{what}: row {row} has {v}; every number must be finite"
                ));
            }
            if let Some(f) = r[..n].iter().find(|f| **f < 0.0) {
                return Err(format!(
                    "{what}: row {row} has the fraction {f}; fractions are 0 to 1"
                ));
            }
            let sum: f64 = r[..n].iter().sum();
            if (sum - 1.0).abs() > SUM_TOLERANCE {
                return Err(format!(
                    "{what}: row {row}'s fractions add up to {sum}; each row's {n} fractions must add up to 1"
                ));
            }
        }
        let values: Vec<f64> = rows.iter().map(|r| r[n]).collect();
        let rising = direction(&values, what)?;
        let at: Vec<(f64, f64)> = (0..rows.len()).map(|i| (i as f64, values[i])).collect();
        Ok(MixTable {
            inverse: inverse(&at, rising, what)?,
            rows: rows.iter().map(|r| r[..n].to_vec()).collect(),
        })
    }

    /// Rows from CSV text: `share,value` (header and `#` lines as
    /// [`csv_rows`]).
    pub(crate) fn parse_csv(text: &str, what: &str) -> Result<MixTable, String> {
        MixTable::new(&csv_rows(text, what)?, what)
    }

    /// A path's rows from CSV text: `n` fraction columns, then the value
    /// (a first line that is not numeric is a header; `#` lines skipped).
    pub(crate) fn parse_csv_path(text: &str, n: usize, what: &str) -> Result<MixTable, String> {
        let mut rows = Vec::new();
        for (line, cells) in csv_cells(text) {
            let nums: Option<Vec<f64>> = cells.iter().map(|c| c.parse::<f64>().ok()).collect();
            match nums {
                Some(v) if v.len() == n + 1 => rows.push(v),
                None if rows.is_empty() && line == first_line(text) => {}
                _ => {
                    return Err(format!(
                        "{what}:{line}: expected {} numbers (the {n} materials' fractions, then the value), got {:?}",
                        n + 1,
                        cells.join(",")
                    ));
                }
            }
        }
        MixTable::path(&rows, n, what)
    }

    /// How many materials the table mixes.
    pub fn materials(&self) -> usize {
        self.rows.first().map_or(2, Vec::len)
    }

    /// The second material's share for `value` (two materials), and
    /// whether `value` was outside the table (then the nearest end row's
    /// share).
    #[inline]
    pub fn share(&self, value: f64) -> (f64, bool) {
        self.inverse.lookup(value)
    }

    /// The fractions for `value` passed to `add(material, fraction)` in
    /// material order, and whether `value` was outside the table (then
    /// the nearest end row's mix).
    #[inline]
    pub fn mix(&self, value: f64, add: impl FnMut(usize, f64)) -> bool {
        let (u, outside) = self.inverse.lookup(value);
        self.mix_at(u, add);
        outside
    }

    /// The rows around position `u` and how far along from the first.
    fn segment(&self, u: f64) -> (&[f64], &[f64], f64) {
        let last = self.rows.len() - 1;
        let i = (u.max(0.0).floor() as usize).min(last.saturating_sub(1));
        let t = (u - i as f64).clamp(0.0, 1.0);
        (&self.rows[i], &self.rows[(i + 1).min(last)], t)
    }

    /// Bounds of each material's fraction for the values in `v`, passed
    /// to `add(material, bound)`: a point for a one-value interval. The
    /// position along the rows is monotonic in the value, and a fraction
    /// is linear between rows, so it lies between its values at the two
    /// ends' positions and at the rows between (widened by 10⁻¹² for the
    /// rounding of the interpolation).
    pub fn mix_bounds(&self, v: Interval, mut add: impl FnMut(usize, Interval)) {
        if v.lo == v.hi {
            self.mix(v.lo, |m, f| add(m, Interval::point(f)));
            return;
        }
        let (lo, hi) = if v.lo.is_nan() || v.hi.is_nan() {
            // The whole path (shares 0 to 1 for two materials).
            (0.0, (self.rows.len().max(2) - 1) as f64)
        } else {
            let (a, z) = (self.inverse.lookup(v.lo).0, self.inverse.lookup(v.hi).0);
            (a.min(z), a.max(z))
        };
        let mut ends = [[0.0; 2]; crate::model::MAX_MATERIALS];
        for (k, u) in [lo, hi].into_iter().enumerate() {
            self.mix_at(u, |m, f| ends[m][k] = f);
        }
        for (m, e) in ends.iter().enumerate().take(self.materials()) {
            let (mut l, mut h) = (e[0].min(e[1]), e[0].max(e[1]));
            // Rows strictly inside (lo, hi): the path's corners.
            for r in self
                .rows
                .iter()
                .take(hi.ceil() as usize)
                .skip(lo.floor() as usize + 1)
            {
                (l, h) = (l.min(r[m]), h.max(r[m]));
            }
            add(m, Interval::new((l - 1e-12).max(0.0), (h + 1e-12).min(1.0)));
        }
    }

    /// The fractions at position `u` along the rows (the second
    /// material's share for two materials).
    #[inline]
    fn mix_at(&self, u: f64, mut add: impl FnMut(usize, f64)) {
        if self.rows.is_empty() {
            add(0, 1.0 - u);
            add(1, u);
            return;
        }
        let (a, b, t) = self.segment(u);
        for (m, (x, y)) in a.iter().zip(b).enumerate() {
            add(m, x + t * (y - x));
        }
    }

    /// Smallest and largest value of the table.
    pub fn value_range(&self) -> (f64, f64) {
        self.inverse.input_range()
    }
}

/// The 1-based number of the first line [`csv_cells`] yields.
fn first_line(text: &str) -> usize {
    csv_cells(text).next().map_or(0, |(n, _)| n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_rows_give_the_linear_mix() {
        let t = MixTable::new(&[(0.0, 30.0), (1.0, 95.0)], "t").unwrap();
        // (62.5 − 30) / 65 = 0.5.
        let rows = [(30.0, 0.0, false), (95.0, 1.0, false), (62.5, 0.5, false)];
        crate::attribute::assert_maps(|v| t.share(v), &rows);
        assert!((t.share(43.0).0 - 0.2).abs() < 1e-15);
    }

    #[test]
    fn a_kink_is_followed_segment_by_segment() {
        // Shares 0, 0.5, 1 measure 30, 50, 95: below 50 the share rises
        // 0.5 per 20, above it 0.5 per 45.
        let t = MixTable::new(&[(0.0, 30.0), (0.5, 50.0), (1.0, 95.0)], "t").unwrap();
        let rows = [(40.0, 0.25, false), (50.0, 0.5, false), (72.5, 0.75, false)];
        crate::attribute::assert_maps(|v| t.share(v), &rows);
    }

    #[test]
    fn falling_values_invert_too() {
        let t = MixTable::new(&[(0.0, 90.0), (0.5, 60.0), (1.0, 20.0)], "t").unwrap();
        let rows = [
            (75.0, 0.25, false),
            (40.0, 0.75, false),
            (100.0, 0.0, true),
            (10.0, 1.0, true),
        ];
        crate::attribute::assert_maps(|v| t.share(v), &rows);
        assert_eq!(t.value_range(), (20.0, 90.0));
    }

    #[test]
    fn clamps_at_the_ends() {
        let t = MixTable::new(&[(0.0, 30.0), (1.0, 95.0)], "t").unwrap();
        crate::attribute::assert_maps(|v| t.share(v), &[(20.0, 0.0, true), (99.0, 1.0, true)]);
    }

    #[test]
    fn refuses_tables_it_cannot_invert() {
        let e = MixTable::new(
            &[(0.0, 30.0), (0.4, 60.0), (0.7, 55.0), (1.0, 95.0)],
            "mix.csv",
        )
        .unwrap_err();
        assert!(
            e.contains("mix.csv: rows 2 and 3 (values 60 then 55)"),
            "{e}"
        );
        assert!(e.contains("must rise strictly"), "{e}");
        let e = MixTable::new(&[(0.0, 30.0), (0.5, 30.0)], "t").unwrap_err();
        assert!(e.contains("rows 1 and 2"), "{e}");
        let e = MixTable::new(&[(0.0, 30.0), (1.5, 40.0)], "t").unwrap_err();
        assert!(e.contains("row 2 has share 1.5"), "{e}");
        let e = MixTable::new(&[(0.5, 30.0), (0.2, 40.0)], "t").unwrap_err();
        assert!(e.contains("shares must rise"), "{e}");
        assert!(MixTable::new(&[(0.0, 30.0)], "t").is_err());
    }

    #[test]
    fn reads_csv_with_bom_header_and_source() {
        let t = MixTable::parse_csv(
            "\u{feff}# source: illustrative\nshare,shore\n0,30\n1,95\n",
            "t",
        )
        .unwrap();
        assert_eq!(t.share(62.5), (0.5, false));
        let e = MixTable::parse_csv("share,shore\n0,30\n1,x\n", "mix.csv").unwrap_err();
        assert!(e.contains("mix.csv:3"), "{e}");
        let e = MixTable::parse_csv("# nothing\n", "mix.csv").unwrap_err();
        assert!(e.contains("0 rows"), "{e}");
    }
}
