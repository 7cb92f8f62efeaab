//! The documented common attribute names that exports read, with their
//! type, unit and the range a value must lie in (pyvcad 3's
//! `DefaultAttributes`, with its units).

use super::{AttributeError, AttributeKind};

/// A common attribute name.
#[derive(Clone, Copy, Debug)]
pub struct Common {
    /// The name.
    pub name: &'static str,
    /// Its type.
    pub kind: AttributeKind,
    /// Its unit, for messages and docs.
    pub unit: &'static str,
    /// Smallest allowed value (of every component).
    pub min: f64,
    /// Largest allowed value (of every component).
    pub max: f64,
}

/// The names exports read.
pub const COMMON: [Common; 7] = [
    Common {
        name: "modulus",
        kind: AttributeKind::Scalar,
        unit: "MPa",
        min: 0.0,
        max: f64::INFINITY,
    },
    // A stable isotropic solid has −1 < ν < 0.5.
    Common {
        name: "poissons_ratio",
        kind: AttributeKind::Scalar,
        unit: "",
        min: -1.0,
        max: 0.5,
    },
    Common {
        name: "density",
        kind: AttributeKind::Scalar,
        unit: "g/cm^3",
        min: 0.0,
        max: f64::INFINITY,
    },
    Common {
        name: "shore_hardness",
        kind: AttributeKind::Scalar,
        unit: "Shore",
        min: 0.0,
        max: 100.0,
    },
    Common {
        name: "infill_density",
        kind: AttributeKind::Scalar,
        unit: "%",
        min: 0.0,
        max: 100.0,
    },
    // Absolute zero in °C.
    Common {
        name: "temperature",
        kind: AttributeKind::Scalar,
        unit: "°C",
        min: -273.15,
        max: f64::INFINITY,
    },
    Common {
        name: "color",
        kind: AttributeKind::Vec4,
        unit: "RGBA 0-1",
        min: 0.0,
        max: 1.0,
    },
];

/// The common entry of `name`, if it is one.
pub fn common(name: &str) -> Option<&'static Common> {
    COMMON.iter().find(|c| c.name == name)
}

/// Refuse a value of the wrong type for a common name (`what`: the call,
/// for the message).
pub fn check_kind(name: &str, kind: AttributeKind, what: &str) -> Result<(), AttributeError> {
    match common(name) {
        Some(c) if c.kind != kind => Err(AttributeError {
            node: what.to_owned(),
            message: format!(
                "\"{name}\" is a {} ({}), got a {}; {}",
                c.kind.name(),
                c.unit,
                kind.name(),
                match c.kind {
                    AttributeKind::Scalar => "give a number or a math string",
                    AttributeKind::Vec3 => "give Vec3(x, y, z)",
                    AttributeKind::Vec4 => "give Vec4(r, g, b, a) with each in 0-1",
                }
            ),
        }),
        _ => Ok(()),
    }
}

/// The allowed range of a common name's values, as `(min, max, unit)`.
pub fn range(name: &str) -> Option<(f64, f64, &'static str)> {
    common(name).map(|c| (c.min, c.max, c.unit))
}

/// "0..100 %" or "at least 0 MPa", for messages.
pub fn range_text(lo: f64, hi: f64, unit: &str) -> String {
    if hi.is_infinite() {
        format!("at least {lo} {unit}")
    } else {
        format!("{lo}..{hi} {unit}")
    }
}
