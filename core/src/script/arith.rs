//! Python 3's arithmetic for script numbers, so pyvcad listings port line
//! by line: `/` is true division (two integers give a float: `5 / 2` is
//! 2.5), `%` takes the sign of the divisor (`-7 % 3` is 2), `**` with a
//! negative integer exponent gives a float, and `floor_div(a, b)` is
//! Python's `//` (which Rhai cannot spell: `//` starts a comment).
//! Division by zero is an error, as Python's `ZeroDivisionError`.
//!
//! Rhai's own operators stay for every other type (strings, arrays, Vec3):
//! the engine runs with fast operators off, so these registrations take
//! precedence over its built-in integer forms.

use rhai::{Dynamic, Engine, INT, NativeCallContext as Ctx, Position};

use super::values::{RResult, fail};

const ZERO_DIVISION: &str = "division by zero (Python raises ZeroDivisionError here)";

fn zero(pos: Position) -> RResult<Dynamic> {
    fail(pos, ZERO_DIVISION)
}

/// Python's float `%`: the remainder takes the divisor's sign (CPython's
/// `float_rem`: `fmod`, then moved by one divisor when the signs differ).
pub fn py_fmod(a: f64, b: f64) -> f64 {
    let m = a % b;
    if m != 0.0 {
        if (b < 0.0) != (m < 0.0) { m + b } else { m }
    } else {
        0.0f64.copysign(b)
    }
}

/// Python's float `//` (CPython's `float_floor_div` via `_float_div_mod`):
/// `(a - fmod(a, b)) / b`, stepped down when the remainder's sign differs
/// from the divisor's, then rounded to the nearest integer value so that
/// the quotient is exact (for example `7.0 // 0.1` is 69.0, not 70.0).
pub fn py_floor_div_f(a: f64, b: f64) -> f64 {
    let m = a % b;
    let mut div = (a - m) / b;
    if m != 0.0 && ((b < 0.0) != (m < 0.0)) {
        div -= 1.0;
    }
    if div == 0.0 {
        return 0.0f64.copysign(a / b);
    }
    let f = div.floor();
    if div - f > 0.5 { f + 1.0 } else { f }
}

/// Python's integer `//`: the quotient rounded toward minus infinity.
pub fn py_floor_div_i(a: INT, b: INT) -> Option<INT> {
    let q = a.checked_div(b)?;
    let r = a.checked_rem(b)?;
    Some(if r != 0 && ((r < 0) != (b < 0)) {
        q - 1
    } else {
        q
    })
}

/// Python's integer `%`: the remainder takes the divisor's sign.
pub fn py_mod_i(a: INT, b: INT) -> Option<INT> {
    let r = a.checked_rem(b)?;
    Some(if r != 0 && ((r < 0) != (b < 0)) {
        r + b
    } else {
        r
    })
}

/// Python's `**` on floats, refusing what Python refuses (0 to a negative
/// power) or turns complex (a negative base to a fractional power).
fn py_pow_f(a: f64, b: f64, pos: Position) -> RResult<Dynamic> {
    if a == 0.0 && b < 0.0 {
        return fail(
            pos,
            "0 cannot be raised to a negative power (Python raises ZeroDivisionError here)",
        );
    }
    if a < 0.0 && b.fract() != 0.0 && b.is_finite() {
        return fail(
            pos,
            format!(
                "{a} ** {b}: a negative number to a fractional power is a complex number in Python; \
                 write -((-x) ** p) if you meant the real root"
            ),
        );
    }
    Ok(Dynamic::from_float(a.powf(b)))
}

fn py_pow_i(a: INT, b: INT, pos: Position) -> RResult<Dynamic> {
    if b < 0 {
        return py_pow_f(a as f64, b as f64, pos);
    }
    u32::try_from(b)
        .ok()
        .and_then(|e| a.checked_pow(e))
        .map(Dynamic::from_int)
        .map_or_else(
            || {
                fail(
                    pos,
                    format!(
                        "{a} ** {b} does not fit in a 64-bit integer; write {a}.0 ** {b} for a float"
                    ),
                )
            },
            Ok,
        )
}

/// `a / b` as Python 3 computes it.
fn true_div(a: f64, b: f64, pos: Position) -> RResult<Dynamic> {
    if b == 0.0 {
        return zero(pos);
    }
    Ok(Dynamic::from_float(a / b))
}

fn mod_f(a: f64, b: f64, pos: Position) -> RResult<Dynamic> {
    if b == 0.0 {
        return fail(pos, "modulo by zero (Python raises ZeroDivisionError here)");
    }
    Ok(Dynamic::from_float(py_fmod(a, b)))
}

fn floor_div_f(a: f64, b: f64, pos: Position) -> RResult<Dynamic> {
    if b == 0.0 {
        return zero(pos);
    }
    Ok(Dynamic::from_float(py_floor_div_f(a, b)))
}

#[derive(Clone, Copy)]
enum Op {
    Div,
    Mod,
    Pow,
    FloorDiv,
}

/// `a op b` for two script numbers, integer or float.
fn apply(op: Op, a: &Dynamic, b: &Dynamic, pos: Position) -> RResult<Dynamic> {
    if let (Ok(x), Ok(y)) = (a.as_int(), b.as_int()) {
        return match op {
            Op::Div => true_div(x as f64, y as f64, pos),
            Op::Mod if y == 0 => mod_f(0.0, 0.0, pos),
            // Only i64::MIN % -1 overflows, and its remainder is 0.
            Op::Mod => Ok(Dynamic::from_int(py_mod_i(x, y).unwrap_or(0))),
            Op::Pow => py_pow_i(x, y, pos),
            Op::FloorDiv if y == 0 => zero(pos),
            Op::FloorDiv => py_floor_div_i(x, y).map(Dynamic::from_int).map_or_else(
                || {
                    fail(
                        pos,
                        format!("floor_div({x}, {y}) does not fit in a 64-bit integer"),
                    )
                },
                Ok,
            ),
        };
    }
    let f = |v: &Dynamic| v.as_float().or_else(|_| v.as_int().map(|i| i as f64));
    let (Ok(x), Ok(y)) = (f(a), f(b)) else {
        return fail(pos, "expected two numbers");
    };
    match op {
        Op::Div => true_div(x, y, pos),
        Op::Mod => mod_f(x, y, pos),
        Op::Pow => py_pow_f(x, y, pos),
        Op::FloorDiv => floor_div_f(x, y, pos),
    }
}

/// Register `name` for the four pairs of integer and float.
fn four(engine: &mut Engine, name: &str, op: Op) {
    let call = move |c: &Ctx, a: Dynamic, b: Dynamic| apply(op, &a, &b, c.call_position());
    engine.register_fn(name, move |c: Ctx, a: INT, b: INT| {
        call(&c, a.into(), b.into())
    });
    engine.register_fn(name, move |c: Ctx, a: INT, b: f64| {
        call(&c, a.into(), b.into())
    });
    engine.register_fn(name, move |c: Ctx, a: f64, b: INT| {
        call(&c, a.into(), b.into())
    });
    engine.register_fn(name, move |c: Ctx, a: f64, b: f64| {
        call(&c, a.into(), b.into())
    });
}

/// Register Python's `/`, `%`, `**`, `floor_div` and their assignment forms.
pub fn register(engine: &mut Engine) {
    // Without this, Rhai runs its built-in integer operators directly and
    // never looks at the registrations below.
    engine.set_fast_operators(false);
    four(engine, "/", Op::Div);
    four(engine, "%", Op::Mod);
    four(engine, "**", Op::Pow);
    four(engine, "floor_div", Op::FloorDiv);
    // Python's math functions take integers too (`sqrt(2)`); Rhai's take
    // floats only.
    type Unary = fn(f64) -> f64;
    let unary: [(&str, Unary); 13] = [
        ("sqrt", f64::sqrt),
        ("sin", f64::sin),
        ("cos", f64::cos),
        ("tan", f64::tan),
        ("asin", f64::asin),
        ("acos", f64::acos),
        ("atan", f64::atan),
        ("sinh", f64::sinh),
        ("cosh", f64::cosh),
        ("tanh", f64::tanh),
        ("exp", f64::exp),
        ("ln", f64::ln),
        ("log", f64::log10),
    ];
    for (name, f) in unary {
        engine.register_fn(name, move |x: INT| f(x as f64));
    }
    // Python's one-argument `range(n)` (Rhai has the two- and three-argument
    // forms).
    engine.register_fn("range", |n: INT| 0..n.max(0));
    // `x /= y` and friends: Rhai looks for the assignment form first and
    // would find its built-in integer one; these take any value, act on
    // two numbers, and otherwise call the type's own operator (a Vec3
    // divided by a number, ...).
    for (op, name, base) in [
        (Op::Div, "/=", "/"),
        (Op::Mod, "%=", "%"),
        (Op::Pow, "**=", "**"),
    ] {
        engine.register_fn(
            name,
            move |c: Ctx, a: &mut Dynamic, b: Dynamic| -> RResult<()> {
                let num = |v: &Dynamic| v.is_int() || v.is_float();
                if !num(a) || !num(&b) {
                    // A Vec3 or another type: its own operator.
                    let mut b = b;
                    let r = c.call_native_fn_raw(base, false, &mut [&mut a.clone(), &mut b])?;
                    *a = r;
                    return Ok(());
                }
                *a = apply(op, a, &b, c.call_position())?;
                Ok(())
            },
        );
    }
}
