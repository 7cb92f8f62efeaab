//! The function and constant vocabulary of the expression language (pyvcad 2.3.4's
//! ExprTk subset), the "did you mean" suggestions, and the scalar definitions of the
//! functions that are more than one `f64` method call.

use super::ops::Op;
use super::scalar::EPSILON;

/// How a function name maps onto operations.
#[derive(Clone, Copy, Debug)]
pub(crate) enum FnKind {
    /// A fixed-arity function that is exactly one operation.
    Fixed(Op),
    /// `min`, `max`, `sum`, `mul`: a left fold of the binary operation over one or
    /// more arguments (`min(a, b, c) = min(min(a, b), c)`).
    Fold(Op),
    /// `avg(a, ..., n) = (a + ... + n) / count`, as ExprTk computes it.
    Avg,
}

/// One built-in function.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Function {
    /// Lower-case name.
    pub name: &'static str,
    /// Parameter list for error messages, e.g. `"lo, x, hi"`; empty for variadics.
    pub params: &'static str,
    /// How calls are compiled.
    pub kind: FnKind,
}

impl Function {
    /// The exact argument count, or `None` for "one or more".
    pub(crate) fn arity(&self) -> Option<usize> {
        match self.kind {
            FnKind::Fixed(op) => Some(op.arity()),
            FnKind::Fold(_) | FnKind::Avg => None,
        }
    }
}

const fn f(name: &'static str, params: &'static str, op: Op) -> Function {
    Function {
        name,
        params,
        kind: FnKind::Fixed(op),
    }
}

const fn fold(name: &'static str, op: Op) -> Function {
    Function {
        name,
        params: "",
        kind: FnKind::Fold(op),
    }
}

/// Every built-in function, alphabetically (the order error messages list them in).
pub(crate) const FUNCTIONS: &[Function] = &[
    f("abs", "x", Op::Abs),
    f("acos", "x", Op::Acos),
    f("acosh", "x", Op::Acosh),
    f("asin", "x", Op::Asin),
    f("asinh", "x", Op::Asinh),
    f("atan", "x", Op::Atan),
    f("atan2", "y, x", Op::Atan2),
    f("atanh", "x", Op::Atanh),
    Function {
        name: "avg",
        params: "",
        kind: FnKind::Avg,
    },
    f("ceil", "x", Op::Ceil),
    f("clamp", "lo, x, hi", Op::Clamp),
    f("cos", "x", Op::Cos),
    f("cosh", "x", Op::Cosh),
    f("cot", "x", Op::Cot),
    f("csc", "x", Op::Csc),
    f("deg2rad", "x", Op::Deg2Rad),
    f("equal", "a, b", Op::Equal),
    f("erf", "x", Op::Erf),
    f("erfc", "x", Op::Erfc),
    f("exp", "x", Op::Exp),
    f("expm1", "x", Op::Expm1),
    f("floor", "x", Op::Floor),
    f("frac", "x", Op::Frac),
    f("hypot", "x, y", Op::Hypot),
    f("iclamp", "lo, x, hi", Op::IClamp),
    f("if", "condition, then, else", Op::Select),
    f("inrange", "lo, x, hi", Op::InRange),
    f("log", "x", Op::Ln),
    f("log10", "x", Op::Log10),
    f("log1p", "x", Op::Log1p),
    f("log2", "x", Op::Log2),
    f("logn", "x, base", Op::Logn),
    fold("max", Op::Max),
    fold("min", Op::Min),
    fold("mul", Op::Mul),
    f("ncdf", "x", Op::Ncdf),
    f("pow", "x, y", Op::Pow),
    f("rad2deg", "x", Op::Rad2Deg),
    f("root", "x, n", Op::Root),
    f("round", "x", Op::Round),
    f("roundn", "x, digits", Op::Roundn),
    f("sec", "x", Op::Sec),
    f("sgn", "x", Op::Sgn),
    f("sin", "x", Op::Sin),
    f("sinc", "x", Op::Sinc),
    f("sinh", "x", Op::Sinh),
    f("sqrt", "x", Op::Sqrt),
    fold("sum", Op::Add),
    f("tan", "x", Op::Tan),
    f("tanh", "x", Op::Tanh),
    f("trunc", "x", Op::Trunc),
];

/// Named constants (case-insensitive, reserved: they shadow variables).
pub(crate) const CONSTANTS: &[(&str, f64)] = &[
    ("pi", std::f64::consts::PI),
    ("e", std::f64::consts::E),
    ("epsilon", EPSILON),
    ("inf", f64::INFINITY),
    ("true", 1.0),
    ("false", 0.0),
];

/// Looks up a lower-case function name.
pub(crate) fn function(name: &str) -> Option<&'static Function> {
    FUNCTIONS.iter().find(|f| f.name == name)
}

/// Looks up a lower-case constant name.
pub(crate) fn constant(name: &str) -> Option<f64> {
    CONSTANTS.iter().find(|c| c.0 == name).map(|c| c.1)
}

/// Hand-written hints for names users coming from other languages try.
const HINTS: &[(&str, &str)] = &[
    ("ln", "did you mean 'log'?"),
    ("sign", "did you mean 'sgn'?"),
    ("signum", "did you mean 'sgn'?"),
    ("arcsin", "did you mean 'asin'?"),
    ("arccos", "did you mean 'acos'?"),
    ("arctan", "did you mean 'atan'?"),
    ("power", "did you mean 'pow'?"),
    ("mod", "use the '%' operator, e.g. x % 2"),
    ("fmod", "use the '%' operator, e.g. x % 2"),
    ("average", "did you mean 'avg'?"),
    ("mean", "did you mean 'avg'?"),
    ("lerp", "write it out: a + (b - a) * t"),
    ("mix", "write it out: a + (b - a) * t"),
    (
        "rand",
        "random numbers are not available: expressions must be deterministic",
    ),
    (
        "random",
        "random numbers are not available: expressions must be deterministic",
    ),
    (
        "noise",
        "noise functions are not available: expressions must be deterministic",
    ),
    ("not", "'not' is an operator: write 'not x'"),
];

/// The message for a call to an unknown function `name` (lower-case).
pub(crate) fn unknown_function_message(name: &str, original: &str) -> String {
    if let Some((_, hint)) = HINTS.iter().find(|h| h.0 == name) {
        return format!("unknown function '{original}' ({hint})");
    }
    if let Some(best) = closest(name, FUNCTIONS.iter().map(|f| f.name)) {
        return format!("unknown function '{original}' (did you mean '{best}'?)");
    }
    let names: Vec<&str> = FUNCTIONS.iter().map(|f| f.name).collect();
    format!(
        "unknown function '{original}' (available: {})",
        names.join(", ")
    )
}

/// The message for an unknown variable `name` given the known variable names.
pub(crate) fn unknown_variable_message(name: &str, original: &str, vars: &[String]) -> String {
    let consts: Vec<&str> = CONSTANTS.iter().map(|c| c.0).collect();
    let known = if vars.is_empty() {
        "none".to_string()
    } else {
        vars.join(", ")
    };
    let mut msg = format!(
        "unknown variable '{original}' (known: {known}; constants: {})",
        consts.join(", ")
    );
    let candidates = vars
        .iter()
        .map(String::as_str)
        .chain(consts.iter().copied());
    if name.chars().count() >= 3
        && let Some(best) = closest(name, candidates)
    {
        msg.push_str(&format!("; did you mean '{best}'?"));
    }
    msg
}

/// The candidate within edit distance 2 (1 for short names) of `name`, if any.
fn closest<'a>(name: &str, candidates: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    let limit = if name.chars().count() <= 3 { 1 } else { 2 };
    candidates
        .map(|c| (levenshtein(name, c), c))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// Edit distance (insertions, deletions, substitutions) between two strings.
fn levenshtein(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diag = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let next = (row[j + 1] + 1)
                .min(row[j] + 1)
                .min(diag + usize::from(ca != *cb));
            diag = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_sorted_and_unique() {
        for w in FUNCTIONS.windows(2) {
            assert!(w[0].name < w[1].name, "{} / {}", w[0].name, w[1].name);
        }
    }

    #[test]
    fn suggestions() {
        assert_eq!(
            unknown_function_message("ln", "ln"),
            "unknown function 'ln' (did you mean 'log'?)"
        );
        assert!(unknown_function_message("sqr", "sqr").contains("did you mean 'sqrt'?"));
        assert!(unknown_function_message("foo", "foo").contains("available: abs, acos"));
        assert!(unknown_function_message("rand", "RAND").contains("deterministic"));
        let vars = vec!["x".to_string(), "rho".to_string()];
        let m = unknown_variable_message("q", "q", &vars);
        assert_eq!(
            m,
            "unknown variable 'q' (known: x, rho; constants: pi, e, epsilon, inf, true, false)"
        );
        assert!(unknown_variable_message("rhoo", "rhoo", &vars).ends_with("did you mean 'rho'?"));
    }
}
