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
//! With more than two materials a row would name a full fractions row and
//! the mix would follow the path through them; two materials need only
//! the share.

use super::convert::{Table, check_pairs, csv_rows};

/// A two-material mix table, inverted for lookups by value.
#[derive(Clone, Debug, PartialEq)]
pub struct MixTable {
    /// Value -> share of the second material.
    inverse: Table,
}

impl MixTable {
    /// A table of `(share of the second material, value)` rows; `what`
    /// names it in errors.
    pub fn new(rows: &[(f64, f64)], what: &str) -> Result<MixTable, String> {
        check_pairs(rows, what, "a mix table", "(share, value)")?;
        for (i, (s, _)) in rows.iter().enumerate() {
            if !(0.0..=1.0).contains(s) {
                return Err(format!(
                    "{what}: row {} has share {s}; the first column is the second material's share, 0 (pure first material) to 1 (pure second)",
                    i + 1
                ));
            }
        }
        if let Some(i) = rows.windows(2).position(|w| w[1].0 <= w[0].0) {
            return Err(format!(
                "{what}: the shares must rise row by row, but row {} has {} after {}; sort the rows by share and merge repeated shares",
                i + 2,
                rows[i + 1].0,
                rows[i].0
            ));
        }
        let rising = rows[1].1 > rows[0].1;
        let breaks = |a: f64, b: f64| if rising { b <= a } else { b >= a };
        if let Some(i) = rows.windows(2).position(|w| breaks(w[0].1, w[1].1)) {
            let way = if rising { "rise" } else { "fall" };
            return Err(format!(
                "{what}: rows {} and {} (values {} then {}) break the order: the values must {way} strictly with the share (rows 1 and 2 set the direction) so that each value has one mix; a table whose value turns back cannot be inverted: keep the monotonic part of the table",
                i + 1,
                i + 2,
                rows[i].1,
                rows[i + 1].1
            ));
        }
        let mut pairs: Vec<(f64, f64)> = rows.iter().map(|(s, v)| (*v, *s)).collect();
        if !rising {
            pairs.reverse();
        }
        Ok(MixTable {
            inverse: Table::new(&pairs, what)?,
        })
    }

    /// Rows from CSV text: `share,value` (header and `#` lines as
    /// [`csv_rows`]).
    pub fn parse_csv(text: &str, what: &str) -> Result<MixTable, String> {
        MixTable::new(&csv_rows(text, what)?, what)
    }

    /// The second material's share for `value`, and whether `value` was
    /// outside the table (then the nearest end row's share).
    #[inline]
    pub fn share(&self, value: f64) -> (f64, bool) {
        self.inverse.lookup(value)
    }

    /// Smallest and largest value of the table.
    pub fn value_range(&self) -> (f64, f64) {
        self.inverse.input_range()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_rows_give_the_linear_mix() {
        let t = MixTable::new(&[(0.0, 30.0), (1.0, 95.0)], "t").unwrap();
        assert_eq!(t.share(30.0), (0.0, false));
        assert_eq!(t.share(95.0), (1.0, false));
        // (62.5 − 30) / 65 = 0.5.
        assert_eq!(t.share(62.5), (0.5, false));
        assert!((t.share(43.0).0 - 0.2).abs() < 1e-15);
    }

    #[test]
    fn a_kink_is_followed_segment_by_segment() {
        // Shares 0, 0.5, 1 measure 30, 50, 95: below 50 the share rises
        // 0.5 per 20, above it 0.5 per 45.
        let t = MixTable::new(&[(0.0, 30.0), (0.5, 50.0), (1.0, 95.0)], "t").unwrap();
        assert_eq!(t.share(40.0), (0.25, false));
        assert_eq!(t.share(50.0), (0.5, false));
        assert_eq!(t.share(72.5), (0.75, false));
    }

    #[test]
    fn falling_values_invert_too() {
        let t = MixTable::new(&[(0.0, 90.0), (0.5, 60.0), (1.0, 20.0)], "t").unwrap();
        assert_eq!(t.share(75.0), (0.25, false));
        assert_eq!(t.share(40.0), (0.75, false));
        assert_eq!(t.share(100.0), (0.0, true));
        assert_eq!(t.share(10.0), (1.0, true));
        assert_eq!(t.value_range(), (20.0, 90.0));
    }

    #[test]
    fn clamps_at_the_ends() {
        let t = MixTable::new(&[(0.0, 30.0), (1.0, 95.0)], "t").unwrap();
        assert_eq!(t.share(20.0), (0.0, true));
        assert_eq!(t.share(99.0), (1.0, true));
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
