//! Element size from material heterogeneity.
//!
//! Mixed (graded) regions need small elements to resolve the stiffness
//! gradient; pure regions can be coarse. The measure is the normalised
//! distance of the fraction vector from the even mix:
//!
//! ```text
//! h = sqrt( Σ_i (f_i − 1/n)² ) / sqrt(1 − 1/n)        n = materials in the model
//! ```
//!
//! `Σ_i (f_i − 1/n)²` is largest at a vertex of the simplex (one material
//! pure): `(1 − 1/n)² + (n − 1)/n² = 1 − 1/n`, so `h ∈ [0, 1]`; h = 1 pure,
//! h = 0 evenly mixed. For n = 1 the formula is 0/0: a one-material design is
//! pure everywhere, so h = 1 (coarsest). Fractions are normalised by their
//! sum first, so a partly void mix is measured among the materials present.
//!
//! The edge length is `L = min_cell + h (max_cell − min_cell)`, or a user math
//! string of `h`; either is clamped to `[min_cell, max_cell]` (the lattice
//! cannot go finer than `min_cell`, and `max_cell` sets the coarsest level).

use volcad_core::expr::Expr;

use crate::job::ExportError;

/// Heterogeneity of one fraction vector (see the module doc).
pub fn heterogeneity(fracs: &[f64]) -> f64 {
    let n = fracs.len();
    if n <= 1 {
        return 1.0;
    }
    let sum: f64 = fracs.iter().sum();
    if sum.is_nan() || sum <= 0.0 {
        return 1.0;
    }
    let inv_n = 1.0 / n as f64;
    let ss: f64 = fracs.iter().map(|f| (f / sum - inv_n).powi(2)).sum();
    (ss / (1.0 - inv_n)).sqrt().clamp(0.0, 1.0)
}

/// The compiled sizing rule `h ↦ L`.
#[derive(Clone)]
pub struct SizeRule {
    min_cell: f64,
    max_cell: f64,
    expr: Option<Expr>,
    scale: f64,
}

impl std::fmt::Debug for SizeRule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SizeRule")
            .field("min_cell", &self.min_cell)
            .field("max_cell", &self.max_cell)
            .field("expr", &self.expr.as_ref().map(|e| e.source()))
            .field("scale", &self.scale)
            .finish()
    }
}

impl SizeRule {
    /// The linear rule, or `expr` (a math string of `h`) when given.
    pub fn new(min_cell: f64, max_cell: f64, expr: Option<&str>) -> Result<Self, ExportError> {
        if !(min_cell.is_finite() && min_cell > 0.0) {
            return Err(ExportError::param(
                "--min-cell",
                format!("must be a length > 0 mm, got {min_cell}"),
            ));
        }
        if !(max_cell.is_finite() && max_cell >= min_cell) {
            return Err(ExportError::param(
                "--max-cell",
                format!("must be ≥ --min-cell ({min_cell} mm), got {max_cell}"),
            ));
        }
        let expr = match expr {
            Some(src) => {
                let e = Expr::compile(src, &["h"])
                    .map_err(|e| ExportError::param("--sizing", format!("\"{src}\": {e} (a math string of h, 0 mixed … 1 pure, giving the edge length in mm)")))?;
                // NaN has no length to clamp: refused as `--infill` refuses
                // it, at the first of 101 heterogeneities where it appears.
                if let Some(h) = (0..=100)
                    .map(|i| f64::from(i) / 100.0)
                    .find(|&h| e.eval(&[h]).is_nan())
                {
                    return Err(ExportError::param(
                        "--sizing",
                        format!(
                            "\"{src}\" gives NaN at h = {h}; write an edge length in mm for every h in 0..=1"
                        ),
                    ));
                }
                Some(e)
            }
            None => None,
        };
        Ok(Self {
            min_cell,
            max_cell,
            expr,
            scale: 1.0,
        })
    }

    /// Edge length for heterogeneity `h`, clamped to `[min_cell, max_cell]`.
    /// A NaN from a user expression falls back to `max_cell`.
    pub fn length(&self, h: f64) -> f64 {
        let l = match &self.expr {
            Some(e) => e.eval(&[h]),
            None => self.min_cell + h * (self.max_cell - self.min_cell),
        };
        self.scale
            * if l.is_nan() {
                self.max_cell
            } else {
                l.clamp(self.min_cell, self.max_cell)
            }
    }

    /// The same rule with every length multiplied by `s` (the estimate meshes
    /// a coarser copy: counts scale by `s³`).
    pub fn scaled(&self, s: f64) -> SizeRule {
        SizeRule {
            scale: self.scale * s,
            ..self.clone()
        }
    }

    /// Smallest length.
    pub fn min_cell(&self) -> f64 {
        self.scale * self.min_cell
    }

    /// Largest length.
    pub fn max_cell(&self) -> f64 {
        self.scale * self.max_cell
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heterogeneity_ends_and_middle() {
        assert_eq!(heterogeneity(&[1.0]), 1.0);
        assert!((heterogeneity(&[1.0, 0.0]) - 1.0).abs() < 1e-12);
        assert!(heterogeneity(&[0.5, 0.5]).abs() < 1e-12);
        // n = 2: h = |f1 − f2|.
        assert!((heterogeneity(&[0.8, 0.2]) - 0.6).abs() < 1e-12);
        assert!((heterogeneity(&[0.0, 0.0, 1.0]) - 1.0).abs() < 1e-12);
        assert!(heterogeneity(&[1.0 / 3.0; 3]).abs() < 1e-12);
        // Two of three evenly mixed: halfway.
        assert!((heterogeneity(&[0.5, 0.5, 0.0]) - 0.5).abs() < 1e-12);
        // Partly void: measured among the materials present.
        assert!(heterogeneity(&[0.25, 0.25]).abs() < 1e-12);
    }

    #[test]
    fn rule_linear_expr_and_errors() {
        let r = SizeRule::new(0.5, 4.0, None).unwrap();
        assert_eq!(r.length(0.0), 0.5);
        assert_eq!(r.length(1.0), 4.0);
        let r = SizeRule::new(0.5, 4.0, Some("0.5 + 3.5*h*h")).unwrap();
        assert!((r.length(0.5) - 1.375).abs() < 1e-12);
        let r = SizeRule::new(0.5, 4.0, Some("100")).unwrap();
        assert_eq!(r.length(0.3), 4.0);
        assert!(
            SizeRule::new(0.5, 4.0, Some("h +"))
                .unwrap_err()
                .to_string()
                .contains("--sizing")
        );
        assert!(SizeRule::new(0.0, 4.0, None).is_err());
        assert!(SizeRule::new(2.0, 1.0, None).is_err());
    }
}
