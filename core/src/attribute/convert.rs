//! Conversions between attributes (pyvcad 3's `AttributeModifier` with a
//! `LookupTableConverter` or `ExpressionConverter`): `Convert(child, from,
//! to, table | "expr")` sets `to` on a node from the `from` value below it.
//! A table is piecewise linear in its rows, clamped at its ends; the
//! evaluator counts the clamped samples so a caller can warn.

/// A piecewise-linear lookup table with strictly increasing inputs.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    xs: Vec<f64>,
    ys: Vec<f64>,
}

impl Table {
    /// A table of `(input, output)` rows; `what` names it in errors.
    pub(crate) fn new(rows: &[(f64, f64)], what: &str) -> Result<Table, String> {
        check_pairs(rows, what, "a lookup table", "(input, output)")?;
        check_rising(rows, what, "input")?;
        Ok(Table {
            xs: rows.iter().map(|r| r.0).collect(),
            ys: rows.iter().map(|r| r.1).collect(),
        })
    }

    /// Rows from CSV text (see [`csv_rows`]).
    pub(crate) fn parse_csv(text: &str, what: &str) -> Result<Table, String> {
        Table::new(&csv_rows(text, what)?, what)
    }

    /// The output at `x`, and whether `x` was outside the inputs (then the
    /// nearest end's output).
    #[inline]
    pub fn lookup(&self, x: f64) -> (f64, bool) {
        let n = self.xs.len();
        if x <= self.xs[0] {
            return (self.ys[0], x < self.xs[0]);
        }
        if x >= self.xs[n - 1] {
            return (self.ys[n - 1], x > self.xs[n - 1]);
        }
        // First input above x: the segment is (i − 1, i).
        let i = self.xs.partition_point(|v| *v <= x);
        let t = (x - self.xs[i - 1]) / (self.xs[i] - self.xs[i - 1]);
        (self.ys[i - 1] + t * (self.ys[i] - self.ys[i - 1]), false)
    }

    /// Smallest and largest output.
    pub fn output_range(&self) -> (f64, f64) {
        self.ys
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| {
                (lo.min(*y), hi.max(*y))
            })
    }

    /// Smallest and largest input.
    pub fn input_range(&self) -> (f64, f64) {
        (self.xs[0], self.xs[self.xs.len() - 1])
    }
}

/// The non-empty lines of CSV text that are not `#` comments, as the
/// 1-based line number and the trimmed cells; a byte-order mark is
/// skipped.
pub(crate) fn csv_cells(text: &str) -> impl Iterator<Item = (usize, Vec<&str>)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    text.lines().enumerate().filter_map(|(n, line)| {
        let line = line.trim();
        (!line.is_empty() && !line.starts_with('#'))
            .then(|| (n + 1, line.split(',').map(str::trim).collect()))
    })
}

/// Rows of two numeric columns from CSV text ([`csv_cells`]): a first line
/// that is not numeric is a header, and lines starting with `#` (the
/// source of the numbers) are skipped; `what` names the file in errors,
/// with the 1-based line.
pub(crate) fn csv_rows(text: &str, what: &str) -> Result<Vec<(f64, f64)>, String> {
    let mut rows = Vec::new();
    let mut header = false;
    for (n, cells) in csv_cells(text) {
        let nums: Option<Vec<f64>> = cells.iter().map(|c| c.parse::<f64>().ok()).collect();
        match nums {
            Some(v) if v.len() == 2 => rows.push((v[0], v[1])),
            None if rows.is_empty() && !header => header = true,
            _ => {
                return Err(format!(
                    "{what}:{n}: expected two numbers `input,output`, got {:?}",
                    cells.join(",")
                ));
            }
        }
    }
    Ok(rows)
}

/// Refuse fewer than 2 rows or a number that is not finite (`table`,
/// `pair`: how the message names the table and its rows).
pub(super) fn check_pairs(
    rows: &[(f64, f64)],
    what: &str,
    table: &str,
    pair: &str,
) -> Result<(), String> {
    if rows.len() < 2 {
        return Err(format!(
            "{what} has {} rows; {table} needs at least 2 {pair} rows",
            rows.len()
        ));
    }
    for (i, (x, y)) in rows.iter().enumerate() {
        if !x.is_finite() || !y.is_finite() {
            return Err(format!(
                "{what}: row {} ({x}, {y}) is not a pair of finite numbers",
                i + 1
            ));
        }
    }
    Ok(())
}

/// Refuse rows whose first column does not rise strictly (`key`: how the
/// message names that column, singular).
pub(super) fn check_rising(rows: &[(f64, f64)], what: &str, key: &str) -> Result<(), String> {
    match rows.windows(2).position(|w| w[1].0 <= w[0].0) {
        Some(i) => Err(format!(
            "{what}: the {key}s must rise row by row, but row {} has {} after {}; sort the rows by {key} and merge repeated {key}s",
            i + 2,
            rows[i + 1].0,
            rows[i].0
        )),
        None => Ok(()),
    }
}

/// How a conversion maps its input.
#[derive(Clone, Debug)]
pub enum ConvMap {
    /// A lookup table.
    Table(std::sync::Arc<Table>),
    /// A math string of the coordinates and the input attribute's name.
    Expr(String),
    /// From the material fractions (`from` is `"fractions"`): a mixing
    /// rule over one value per material.
    Mix {
        /// Voigt (`Σ fᵢvᵢ`, parallel) or Reuss (`1 / Σ fᵢ/vᵢ`, series).
        reuss: bool,
        /// `(material id, value)`.
        values: Vec<(crate::material::MaterialId, f64)>,
    },
}

/// The input name of a conversion from material fractions.
pub const FRACTIONS: &str = "fractions";

/// Voigt's or Reuss's mix of `values` (one per fraction), over the
/// fractions given (normalised by their sum, so materials without a value
/// do not count); NaN where none has a value.
#[inline]
pub fn mix(reuss: bool, fractions: &[f64], values: &[f64]) -> f64 {
    let (mut total, mut acc) = (0.0, 0.0);
    for (f, v) in fractions.iter().zip(values) {
        total += f;
        acc += if reuss { f / v } else { f * v };
    }
    if total <= 0.0 {
        f64::NAN
    } else if reuss {
        total / acc
    } else {
        acc / total
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_interpolates_and_clamps() {
        let t = Table::new(&[(20.0, 0.0), (60.0, 0.5), (90.0, 1.0)], "t").unwrap();
        crate::attribute::assert_maps(
            |x| t.lookup(x),
            &[
                (40.0, 0.25, false),
                (75.0, 0.75, false),
                (60.0, 0.5, false),
                (10.0, 0.0, true),
                (95.0, 1.0, true),
            ],
        );
    }

    #[test]
    fn bad_tables_are_refused() {
        let e = Table::new(&[(20.0, 0.0), (10.0, 0.5)], "t.csv").unwrap_err();
        assert!(e.contains("row 2 has 10 after 20"), "{e}");
        assert!(Table::new(&[(1.0, 1.0)], "t").is_err());
        let t = Table::parse_csv("# source: illustrative\nshore,frac\n20,0\n90,1\n", "t").unwrap();
        assert_eq!(t.lookup(55.0), (0.5, false));
        let e = Table::parse_csv("a,b\n1,2\n3,x\n", "t.csv").unwrap_err();
        assert!(e.contains("t.csv:3"), "{e}");
    }
}
