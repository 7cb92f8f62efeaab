//! The operation set shared by the syntax tree, the constant folder and the tape, with
//! the one authoritative definition of each operation's scalar value.
//!
//! Folding and tape evaluation both call [`Op::apply`], so a folded constant is
//! bit-identical to what the tape would have computed at run time.

use super::scalar;

/// `1.0` for true, `0.0` for false.
#[inline(always)]
pub(crate) fn b2f(b: bool) -> f64 {
    if b { 1.0 } else { 0.0 }
}

/// ExprTk truthiness: anything that is not zero (NaN included) is true.
#[inline(always)]
pub(crate) fn truthy(v: f64) -> bool {
    v != 0.0
}

/// π/180, the factor of `deg2rad`.
pub(crate) const DEG2RAD: f64 = std::f64::consts::PI / 180.0;
/// 180/π, the factor of `rad2deg`.
pub(crate) const RAD2DEG: f64 = 180.0 / std::f64::consts::PI;

/// Defines [`Op`] together with `Op::ALL`, the list of every variant in order.
macro_rules! define_ops {
    ($($(#[$doc:meta])* $name:ident,)*) => {
        /// One operation. Operands are called `a`, `b`, `c` in argument order; `imm` is
        /// the immediate constant of the tape-only `...C` forms.
        ///
        /// The first group only appears on the tape: loads and "operation with a
        /// constant" forms that save a register load per evaluation. Everything else also
        /// appears in the syntax tree.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        #[repr(u8)]
        pub(crate) enum Op {
            $($(#[$doc])* $name,)*
        }

        impl Op {
            /// Every operation, in declaration order (for exhaustive tests).
            #[cfg(test)]
            pub(crate) const ALL: &[Op] = &[$(Op::$name,)*];
        }
    };
}

define_ops! {
    // --- tape only ---
    /// Load variable slot `a` (handled by the evaluator, which owns the slots).
    Var,
    /// Load `imm`.
    Const,
    /// `a + imm` (also `a - c`, as `a + (-c)`, which IEEE defines identically).
    AddC,
    /// `imm - a`.
    SubCR,
    /// `a * imm`.
    MulC,
    /// `a / imm`.
    DivRC,
    /// `imm / a`.
    DivCR,
    /// `min(a, imm)`.
    MinC,
    /// `max(a, imm)`.
    MaxC,
    /// `a ^ imm`.
    PowC,
    /// `a < imm ? imm : a`: lower half of `clamp` with constant bounds.
    ClampLoC,
    /// `a > imm ? imm : a`: upper half of `clamp` with constant bounds.
    ClampHiC,

    // --- unary ---
    /// `-a`.
    Neg,
    /// `not a`: 1 when `a == 0`, else 0.
    Not,
    /// `|a|`.
    Abs,
    /// `a * a` (from `a^2`, `pow(a, 2)` or `a*a`).
    Square,
    /// `sqrt(a)`.
    Sqrt,
    /// `ceil(a)`.
    Ceil,
    /// `floor(a)`.
    Floor,
    /// `round(a)`, halves away from zero.
    Round,
    /// `trunc(a)`.
    Trunc,
    /// `frac(a) = a - trunc(a)`.
    Frac,
    /// `sgn(a)`: -1, 0 or 1 (0 for NaN).
    Sgn,
    /// `e^a`.
    Exp,
    /// `e^a - 1`, accurate near 0.
    Expm1,
    /// Natural logarithm (`log`).
    Ln,
    /// `log10(a)`.
    Log10,
    /// `log2(a)`.
    Log2,
    /// `ln(1 + a)`, accurate near 0.
    Log1p,
    /// `sin(a)`.
    Sin,
    /// `cos(a)`.
    Cos,
    /// `tan(a)`.
    Tan,
    /// `asin(a)`.
    Asin,
    /// `acos(a)`.
    Acos,
    /// `atan(a)`.
    Atan,
    /// `sinh(a)`.
    Sinh,
    /// `cosh(a)`.
    Cosh,
    /// `tanh(a)`.
    Tanh,
    /// `asinh(a)`.
    Asinh,
    /// `acosh(a)`.
    Acosh,
    /// `atanh(a)`.
    Atanh,
    /// `1 / cos(a)`.
    Sec,
    /// `1 / sin(a)`.
    Csc,
    /// `1 / tan(a)`.
    Cot,
    /// `sin(a) / a`, 1 for `|a| < f64::EPSILON`.
    Sinc,
    /// `a * π/180`.
    Deg2Rad,
    /// `a * 180/π`.
    Rad2Deg,
    /// Error function.
    Erf,
    /// Complementary error function `1 - erf(a)`.
    Erfc,
    /// Standard normal CDF `Φ(a) = erfc(-a/√2) / 2`.
    Ncdf,

    // --- binary ---
    /// `a + b`.
    Add,
    /// `a - b`.
    Sub,
    /// `a * b`.
    Mul,
    /// `a / b`.
    Div,
    /// `a % b`: C `fmod`, result has the sign of `a`.
    Mod,
    /// `a ^ b`, `pow(a, b)`.
    Pow,
    /// `min(a, b)` (IEEE minNum: a NaN operand is ignored).
    Min,
    /// `max(a, b)` (IEEE maxNum).
    Max,
    /// `atan2(a, b)` = angle of the point `(x = b, y = a)`.
    Atan2,
    /// `hypot(a, b) = sqrt(a² + b²)` without overflow.
    Hypot,
    /// `root(a, b)`: the `b`-th root of `a` (odd integer roots of negatives allowed).
    Root,
    /// `logn(a, b) = ln(a) / ln(b)`.
    Logn,
    /// `roundn(a, b)`: round `a` to `floor(b)` decimals (clamped to 0..=16).
    Roundn,
    /// `equal(a, b)`: `|a - b| <= 1e-10 · max(1, |a|, |b|)`, or `a == b`.
    Equal,
    /// `a == b` (exact).
    Eq,
    /// `a != b`.
    Ne,
    /// `a < b`.
    Lt,
    /// `a <= b`.
    Le,
    /// `a > b`.
    Gt,
    /// `a >= b`.
    Ge,
    /// `a and b`.
    And,
    /// `a or b`.
    Or,
    /// `a xor b`.
    Xor,
    /// `a nand b`.
    Nand,
    /// `a nor b`.
    Nor,
    /// `a xnor b`.
    Xnor,

    // --- ternary ---
    /// `a ? b : c`, `if(a, b, c)`.
    Select,
    /// `clamp(a = lo, b = x, c = hi)`: `x < lo ? lo : (x > hi ? hi : x)`.
    Clamp,
    /// `iclamp(lo, x, hi)`: inside `(lo, hi)` snap to the nearer bound (ties to `hi`),
    /// otherwise `x`.
    IClamp,
    /// `inrange(lo, x, hi)`: 1 when `lo <= x <= hi`, else 0 (0 for NaN).
    InRange,
}

impl Op {
    /// Number of register operands in the syntax tree / SSA form.
    pub(crate) fn arity(self) -> usize {
        use Op::*;
        match self {
            Var | Const => 0,
            AddC | SubCR | MulC | DivRC | DivCR | MinC | MaxC | PowC | ClampLoC | ClampHiC => 1,
            Neg | Not | Abs | Square | Sqrt | Ceil | Floor | Round | Trunc | Frac | Sgn | Exp
            | Expm1 | Ln | Log10 | Log2 | Log1p | Sin | Cos | Tan | Asin | Acos | Atan | Sinh
            | Cosh | Tanh | Asinh | Acosh | Atanh | Sec | Csc | Cot | Sinc | Deg2Rad | Rad2Deg
            | Erf | Erfc | Ncdf => 1,
            Add | Sub | Mul | Div | Mod | Pow | Min | Max | Atan2 | Hypot | Root | Logn
            | Roundn | Equal | Eq | Ne | Lt | Le | Gt | Ge | And | Or | Xor | Nand | Nor | Xnor => {
                2
            }
            Select | Clamp | IClamp | InRange => 3,
        }
    }

    /// Whether `op(a, b) == op(b, a)` bit for bit, so CSE may canonicalise the order.
    pub(crate) fn is_commutative(self) -> bool {
        use Op::*;
        matches!(
            self,
            Add | Mul | Min | Max | Hypot | Equal | Eq | Ne | And | Or | Xor | Nand | Nor | Xnor
        )
    }

    /// The scalar value of this operation. `Var` is not handled here (it needs the
    /// slot array) and yields NaN.
    #[inline(always)]
    pub(crate) fn apply(self, a: f64, b: f64, c: f64, imm: f64) -> f64 {
        use Op::*;
        match self {
            Var => f64::NAN,
            Const => imm,
            AddC => a + imm,
            SubCR => imm - a,
            MulC => a * imm,
            DivRC => a / imm,
            DivCR => imm / a,
            MinC => a.min(imm),
            MaxC => a.max(imm),
            PowC => a.powf(imm),
            ClampLoC => {
                if a < imm {
                    imm
                } else {
                    a
                }
            }
            ClampHiC => {
                if a > imm {
                    imm
                } else {
                    a
                }
            }
            Neg => -a,
            Not => b2f(!truthy(a)),
            Abs => a.abs(),
            Square => a * a,
            Sqrt => a.sqrt(),
            Ceil => a.ceil(),
            Floor => crate::fastmath::floor(a),
            Round => a.round(),
            Trunc => a.trunc(),
            Frac => a - a.trunc(),
            Sgn => scalar::sgn(a),
            Exp => a.exp(),
            Expm1 => a.exp_m1(),
            Ln => a.ln(),
            Log10 => a.log10(),
            Log2 => a.log2(),
            Log1p => a.ln_1p(),
            Sin => a.sin(),
            Cos => a.cos(),
            Tan => a.tan(),
            Asin => a.asin(),
            Acos => a.acos(),
            Atan => a.atan(),
            Sinh => a.sinh(),
            Cosh => a.cosh(),
            Tanh => a.tanh(),
            Asinh => a.asinh(),
            Acosh => a.acosh(),
            Atanh => a.atanh(),
            Sec => 1.0 / a.cos(),
            Csc => 1.0 / a.sin(),
            Cot => 1.0 / a.tan(),
            Sinc => scalar::sinc(a),
            Deg2Rad => a * DEG2RAD,
            Rad2Deg => a * RAD2DEG,
            Erf => libm::erf(a),
            Erfc => libm::erfc(a),
            Ncdf => scalar::ncdf(a),
            Add => a + b,
            Sub => a - b,
            Mul => a * b,
            Div => a / b,
            Mod => a % b,
            Pow => a.powf(b),
            Min => a.min(b),
            Max => a.max(b),
            Atan2 => a.atan2(b),
            Hypot => a.hypot(b),
            Root => scalar::root(a, b),
            Logn => a.ln() / b.ln(),
            Roundn => scalar::roundn(a, b),
            Equal => b2f(scalar::equal(a, b)),
            Eq => b2f(a == b),
            Ne => b2f(a != b),
            Lt => b2f(a < b),
            Le => b2f(a <= b),
            Gt => b2f(a > b),
            Ge => b2f(a >= b),
            And => b2f(truthy(a) & truthy(b)),
            Or => b2f(truthy(a) | truthy(b)),
            Xor => b2f(truthy(a) ^ truthy(b)),
            Nand => b2f(!(truthy(a) & truthy(b))),
            Nor => b2f(!(truthy(a) | truthy(b))),
            Xnor => b2f(truthy(a) == truthy(b)),
            Select => {
                if truthy(a) {
                    b
                } else {
                    c
                }
            }
            Clamp => scalar::clamp(a, b, c),
            IClamp => scalar::iclamp(a, b, c),
            InRange => b2f(a <= b && b <= c),
        }
    }

    /// Short snake-case name used by the tape listing in `Debug` output
    /// (`DivRC` → `div_rc`, `ClampLoC` → `clamp_lo_c`).
    pub(crate) fn name(self) -> String {
        let mut out = String::new();
        let mut prev_lower = false;
        for ch in format!("{self:?}").chars() {
            if ch.is_ascii_uppercase() && prev_lower {
                out.push('_');
            }
            prev_lower = ch.is_ascii_lowercase();
            out.push(ch.to_ascii_lowercase());
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_ops_listed() {
        assert_eq!(Op::ALL.len(), Op::InRange as usize + 1);
        for (i, op) in Op::ALL.iter().enumerate() {
            assert_eq!(*op as usize, i);
            assert!(op.arity() <= 3);
        }
    }
}
