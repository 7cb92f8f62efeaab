//! The reference's table of what math strings understand: variables,
//! operators, functions and constants.

use super::MathDoc;

/// The names math strings (FGrade, Function, SimulationField) understand.
pub static MATH: &[MathDoc] = &[
    MathDoc {
        name: "x y z",
        summary: "the point, in the node's local frame (mm)",
    },
    MathDoc {
        name: "rho phic",
        summary: "cylindrical radius and angle about z",
    },
    MathDoc {
        name: "r theta phis",
        summary: "spherical radius, polar and azimuth angles",
    },
    MathDoc {
        name: "d",
        summary: "the child's signed distance (FGrade)",
    },
    MathDoc {
        name: "dx dy dz len",
        summary: "interpolated displacement and its length (SimulationField; every CSV column too)",
    },
    MathDoc {
        name: "+ - * / % ^",
        summary: "arithmetic; ^ is power, right-associative",
    },
    MathDoc {
        name: "< <= > >= == !=",
        summary: "comparisons (1 or 0)",
    },
    MathDoc {
        name: "and or not",
        summary: "logic",
    },
    MathDoc {
        name: "c ? a : b, if(c, a, b)",
        summary: "choice",
    },
    MathDoc {
        name: "min max sum avg",
        summary: "of any number of arguments",
    },
    MathDoc {
        name: "clamp(lo, x, hi)",
        summary: "x limited to [lo, hi]",
    },
    MathDoc {
        name: "sin cos tan asin acos atan atan2",
        summary: "trigonometry (radians)",
    },
    MathDoc {
        name: "sinh cosh tanh",
        summary: "hyperbolic functions",
    },
    MathDoc {
        name: "exp log log10 log2 sqrt abs",
        summary: "exponentials, logarithms, roots",
    },
    MathDoc {
        name: "floor ceil round trunc frac sgn",
        summary: "rounding",
    },
    MathDoc {
        name: "pi e epsilon inf",
        summary: "constants",
    },
];
