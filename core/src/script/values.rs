//! Conversions between Rhai values and model values, each failing with a
//! message in the script's words ("Sphere: radius must be a number, got
//! string").

use glam::DVec3;
use rhai::{Dynamic, EvalAltResult, Position};

use crate::node::{Node, Origin};

/// A Rhai error at `pos`.
pub type RResult<T> = Result<T, Box<EvalAltResult>>;

/// `Vec3(x, y, z)` in scripts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vec3(pub DVec3);

/// What a value is, in the script's words ("a string", "a node"):
/// `Dynamic::type_name` gives Rust's names for our own types
/// ("volcad_core::node::Node") and Rhai's for the rest ("i64").
pub fn described(v: &Dynamic) -> String {
    if v.is::<Node>() {
        return "a node".into();
    }
    if let Some(u) = v.read_lock::<super::toplevel::Unassigned>() {
        return format!(
            "`{}`, which has no value yet (assign it above this line)",
            u.0
        );
    }
    match v.type_name() {
        "i64" => "an integer".into(),
        "f64" => "a number".into(),
        "string" => "a string".into(),
        "char" => "a character".into(),
        "bool" => "true or false".into(),
        "array" => "an array".into(),
        "map" => "a map".into(),
        "()" => "nothing".into(),
        "Fn" => "a function".into(),
        // Our other types are named in Rust as in scripts (Vec3,
        // MaterialDefs, LatticeType), after their path.
        other => format!("a {}", other.rsplit("::").next().unwrap_or(other)),
    }
}

/// A runtime error with the script position of the call.
pub fn fail<T>(pos: Position, msg: impl Into<String>) -> RResult<T> {
    Err(Box::new(EvalAltResult::ErrorRuntime(
        Dynamic::from(msg.into()),
        pos,
    )))
}

/// The script origin for nodes made at `pos`.
pub fn origin(pos: Position) -> Option<Origin> {
    Some(Origin {
        line: pos.line()? as u32,
        column: pos.position().unwrap_or(0) as u32,
    })
}

/// A number (integer or float) named `what` for messages.
pub fn num(v: &Dynamic, what: &str, pos: Position) -> RResult<f64> {
    if let Ok(f) = v.as_float() {
        Ok(f)
    } else if let Ok(i) = v.as_int() {
        Ok(i as f64)
    } else {
        fail(
            pos,
            format!("{what} must be a number, got {}", described(v)),
        )
    }
}

/// Largest magnitude of a number a design gives (sizes, positions and
/// moves in mm, angles in degrees, smoothing radii): 10⁹ mm is 1,000 km.
/// Distances square their inputs (|p − c|², the TPMS and tile maps divide
/// and floor), so a size of 1e308 became infinite or NaN at evaluation and
/// an export failed far from the line that gave it.
pub const MAX_MAGNITUDE: f64 = 1e9;

/// A finite number below [`MAX_MAGNITUDE`] in magnitude.
pub fn finite(v: &Dynamic, what: &str, pos: Position) -> RResult<f64> {
    let f = num(v, what, pos)?;
    sane(f, what, pos)
}

/// `f` if it is finite and below [`MAX_MAGNITUDE`] in magnitude.
fn sane(f: f64, what: &str, pos: Position) -> RResult<f64> {
    if !f.is_finite() {
        fail(pos, format!("{what} must be finite, got {f}"))
    } else if f.abs() >= MAX_MAGNITUDE {
        fail(
            pos,
            format!(
                "{what} is {f:e}; give a value below 1e9 in magnitude (sizes are in mm: 1e9 mm is 1,000 km)"
            ),
        )
    } else {
        Ok(f)
    }
}

/// A number > 0.
pub fn positive(v: &Dynamic, what: &str, pos: Position) -> RResult<f64> {
    let f = finite(v, what, pos)?;
    if f > 0.0 {
        Ok(f)
    } else {
        fail(pos, format!("{what} must be > 0, got {f}"))
    }
}

/// A number ≥ 0.
pub fn non_negative(v: &Dynamic, what: &str, pos: Position) -> RResult<f64> {
    let f = finite(v, what, pos)?;
    if f >= 0.0 {
        Ok(f)
    } else {
        fail(pos, format!("{what} must be ≥ 0, got {f}"))
    }
}

/// A Vec3 (or a 3-element array of numbers, as pyvcad's Vec3-from-list).
pub fn vec3(v: &Dynamic, what: &str, pos: Position) -> RResult<DVec3> {
    if let Some(v) = v.clone().try_cast::<Vec3>() {
        // Vec3 arithmetic (`Vec3(1, 0, 0) * 1e308`) makes values that no
        // constructor checked.
        for (c, axis) in v.0.to_array().into_iter().zip(["x", "y", "z"]) {
            sane(c, &format!("{what} ({axis})"), pos)?;
        }
        return Ok(v.0);
    }
    if let Some(a) = v.clone().try_cast::<rhai::Array>()
        && a.len() == 3
    {
        return Ok(DVec3::new(
            finite(&a[0], what, pos)?,
            finite(&a[1], what, pos)?,
            finite(&a[2], what, pos)?,
        ));
    }
    fail(pos, format!("{what} must be a Vec3, got {}", described(v)))
}

/// A material id (0..=255); whether the table has it is checked when the
/// script finishes, against the table it used.
pub fn material(v: &Dynamic, pos: Position) -> RResult<u8> {
    let Ok(i) = v.as_int() else {
        return fail(
            pos,
            format!(
                "material must be an id from materials.id(\"name\"), got {}",
                described(v)
            ),
        );
    };
    if (0..=255).contains(&i) {
        Ok(i as u8)
    } else {
        fail(pos, format!("material id {i} is out of range 0..=255"))
    }
}

/// `v` as an array, or the error that `what` must be an array of `items`.
fn array(v: &Dynamic, what: &str, items: &str, pos: Position) -> RResult<rhai::Array> {
    v.clone().try_cast::<rhai::Array>().map_or_else(
        || {
            fail(
                pos,
                format!("{what} must be an array of {items}, got {}", described(v)),
            )
        },
        Ok,
    )
}

/// A node argument.
pub fn node(v: &Dynamic, what: &str, pos: Position) -> RResult<Node> {
    v.clone().try_cast::<Node>().map_or_else(
        || fail(pos, format!("{what} must be a node, got {}", described(v))),
        Ok,
    )
}

/// An array of nodes.
pub fn nodes(v: &Dynamic, what: &str, pos: Position) -> RResult<Vec<Node>> {
    array(v, what, "nodes", pos)?
        .iter()
        .enumerate()
        .map(|(i, n)| node(n, &format!("{what}[{i}]"), pos))
        .collect()
}

/// A bool.
pub fn boolean(v: &Dynamic, what: &str, pos: Position) -> RResult<bool> {
    v.as_bool().or_else(|_| {
        fail(
            pos,
            format!("{what} must be true or false, got {}", described(v)),
        )
    })
}

/// An array of strings.
pub fn strings(v: &Dynamic, what: &str, pos: Position) -> RResult<Vec<String>> {
    array(v, what, "strings", pos)?
        .iter()
        .enumerate()
        .map(|(i, s)| {
            s.clone()
                .into_string()
                .or_else(|t| fail(pos, format!("{what}[{i}] must be a string, got {t}")))
        })
        .collect()
}

/// An array of material ids.
pub fn materials(v: &Dynamic, what: &str, pos: Position) -> RResult<Vec<u8>> {
    array(v, what, "material ids", pos)?
        .iter()
        .map(|m| material(m, pos))
        .collect()
}
