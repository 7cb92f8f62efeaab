//! The nodes pyvcad 3 added that pyvcad 2 scripts reach for: `Cone`,
//! `Torus`, `PolygonRevolve`, the tapered `Strut` with `CapMode`, `Mirror`,
//! `Identity` and `Sum` (pyvcad 2.3.4 has `Sum`). Names and argument orders
//! are pyvcad's; a leaf takes a trailing material id as pyvcad 2's do.

use glam::DVec3;
use rhai::{Dynamic, Engine, NativeCallContext as Ctx, Position};

use super::nodes_api::{mk, optional_child, register_empty};
use super::values::*;
use crate::node::{CapMode, Node, NodeKind};

/// Register the constructors of this module.
pub fn register_shapes(engine: &mut Engine) {
    register_cone_torus(engine);
    register_revolve(engine);
    register_tapered_strut(engine);
    register_mirror(engine);
    register_identity_sum(engine);
}

fn register_cone_torus(engine: &mut Engine) {
    let cone = |c: &Ctx, a: &Dynamic, h: &Dynamic, m: Option<&Dynamic>| -> RResult<Node> {
        let p = c.call_position();
        let angle = finite(a, "Cone: angle", p)?;
        if !(angle.tan() > 0.0 && angle.tan().is_finite()) {
            return fail(
                p,
                format!(
                    "Cone: angle is the aperture half-angle in radians and needs tan(angle) > 0, got {angle} (for degrees write a * PI() / 180)"
                ),
            );
        }
        Ok(mk(
            NodeKind::Cone {
                angle,
                height: positive(h, "Cone: height", p)?,
                material: m.map_or(Ok(1), |m| material(m, p))?,
            },
            p,
        ))
    };
    engine.register_fn("Cone", move |c: Ctx, a: Dynamic, h: Dynamic| {
        cone(&c, &a, &h, None)
    });
    engine.register_fn("Cone", move |c: Ctx, a: Dynamic, h: Dynamic, m: Dynamic| {
        cone(&c, &a, &h, Some(&m))
    });

    let torus = |c: &Ctx, r1: f64, r2: f64, m: u8| {
        mk(
            NodeKind::Torus {
                major: r1,
                minor: r2,
                material: m,
            },
            c.call_position(),
        )
    };
    engine.register_fn("Torus", move |c: Ctx| torus(&c, 2.0, 1.0, 1));
    let checked =
        move |c: &Ctx, r1: &Dynamic, r2: &Dynamic, m: Option<&Dynamic>| -> RResult<Node> {
            let p = c.call_position();
            Ok(torus(
                c,
                positive(r1, "Torus: major radius r1", p)?,
                positive(r2, "Torus: minor radius r2", p)?,
                m.map_or(Ok(1), |m| material(m, p))?,
            ))
        };
    register_optional_last!(engine, "Torus", checked(r1, r2; m));
}

fn register_revolve(engine: &mut Engine) {
    // pyvcad's default: a unit-radius cylinder centred on the origin.
    engine.register_fn("PolygonRevolve", |c: Ctx| -> RResult<Node> {
        let v = |x: f64, z: f64| DVec3::new(x, 0.0, z);
        Ok(mk(
            NodeKind::PolygonRevolve {
                vertices: vec![v(0.0, -0.5), v(1.0, -0.5), v(1.0, 0.5), v(0.0, 0.5)],
                axis_start: DVec3::new(0.0, 0.0, -0.5),
                axis_end: DVec3::new(0.0, 0.0, 0.5),
                sweep_degrees: 360.0,
                material: 1,
            },
            c.call_position(),
        ))
    });
    let revolve = |c: &Ctx, args: [&Dynamic; 4], m: Option<&Dynamic>| -> RResult<Node> {
        let p = c.call_position();
        let Some(arr) = args[0].clone().try_cast::<rhai::Array>() else {
            return fail(
                p,
                format!(
                    "PolygonRevolve: vertices must be an array of Vec3, got {}",
                    described(args[0])
                ),
            );
        };
        let vertices = arr
            .iter()
            .enumerate()
            .map(|(i, v)| vec3(v, &format!("PolygonRevolve: vertex {i}"), p))
            .collect::<RResult<Vec<_>>>()?;
        let axis_start = vec3(args[1], "PolygonRevolve: axis_start", p)?;
        let axis_end = vec3(args[2], "PolygonRevolve: axis_end", p)?;
        let sweep_degrees = finite(args[3], "PolygonRevolve: sweep_degrees", p)?;
        // Check the profile now, so the error points at this call.
        if let Err(e) = crate::model::check_revolve(&vertices, axis_start, axis_end, sweep_degrees)
        {
            return fail(p, format!("PolygonRevolve: {e}"));
        }
        Ok(mk(
            NodeKind::PolygonRevolve {
                vertices,
                axis_start,
                axis_end,
                sweep_degrees,
                material: m.map_or(Ok(1), |m| material(m, p))?,
            },
            p,
        ))
    };
    engine.register_fn(
        "PolygonRevolve",
        move |c: Ctx, v: Dynamic, a: Dynamic, b: Dynamic, s: Dynamic| {
            revolve(&c, [&v, &a, &b, &s], None)
        },
    );
    engine.register_fn(
        "PolygonRevolve",
        move |c: Ctx, v: Dynamic, a: Dynamic, b: Dynamic, s: Dynamic, m: Dynamic| {
            revolve(&c, [&v, &a, &b, &s], Some(&m))
        },
    );
}

/// A script type named `name` whose values are `name::Variant`.
pub(super) fn register_enum<T: Clone + Send + Sync + 'static, const N: usize>(
    engine: &mut Engine,
    name: &str,
    values: [(&str, T); N],
) {
    engine.register_type_with_name::<T>(name);
    let mut module = rhai::Module::new();
    for (variant, v) in values {
        module.set_var(variant, v);
    }
    engine.register_static_module(name, module.into());
}

fn cap_mode(v: &Dynamic, what: &str, pos: Position) -> RResult<CapMode> {
    v.clone().try_cast::<CapMode>().map_or_else(
        || {
            fail(
                pos,
                format!(
                    "{what} must be CapMode::Sphere, CapMode::HemiSphere or CapMode::Butt, got {}",
                    described(v)
                ),
            )
        },
        Ok,
    )
}

/// Strut(start, end, start_radius, end_radius[, start_cap[, end_cap]][, m]):
/// pyvcad 3's tapered form. pyvcad 2's `Strut(start, end, r, m)` keeps its
/// meaning: a fourth argument that is an integer is the material.
fn register_tapered_strut(engine: &mut Engine) {
    register_enum(
        engine,
        "CapMode",
        [
            ("Sphere", CapMode::Sphere),
            ("HemiSphere", CapMode::HemiSphere),
            ("Butt", CapMode::Butt),
        ],
    );

    engine.register_fn(
        "Strut",
        move |c: Ctx, a: Dynamic, b: Dynamic, r1: Dynamic, r2: Dynamic, x: Dynamic| {
            tapered(&c, &[&a, &b, &r1, &r2, &x])
        },
    );
    engine.register_fn(
        "Strut",
        move |c: Ctx, a: Dynamic, b: Dynamic, r1: Dynamic, r2: Dynamic, x: Dynamic, y: Dynamic| {
            tapered(&c, &[&a, &b, &r1, &r2, &x, &y])
        },
    );
    engine.register_fn(
        "Strut",
        move |c: Ctx,
              a: Dynamic,
              b: Dynamic,
              r1: Dynamic,
              r2: Dynamic,
              x: Dynamic,
              y: Dynamic,
              m: Dynamic| { tapered(&c, &[&a, &b, &r1, &r2, &x, &y, &m]) },
    );
}

/// The plane of `Mirror("x" | "y" | "z", offset)`.
fn axis_plane(axis: &Dynamic, offset: f64, pos: Position) -> RResult<(DVec3, DVec3)> {
    let name = axis
        .clone()
        .into_string()
        .unwrap_or_default()
        .to_lowercase();
    let n = match name.as_str() {
        "x" => DVec3::X,
        "y" => DVec3::Y,
        "z" => DVec3::Z,
        _ => {
            return fail(
                pos,
                format!(
                    "Mirror: axis must be \"x\", \"y\" or \"z\", got {}",
                    if axis.is_string() {
                        format!("\"{name}\"")
                    } else {
                        described(axis)
                    }
                ),
            );
        }
    };
    Ok((n * offset, n))
}

/// The plane of `Mirror(point, normal)` or `Mirror(p0, p1, p2)`.
fn vector_plane(args: &[&Dynamic], pos: Position) -> RResult<(DVec3, DVec3)> {
    if args.len() == 2 {
        let point = vec3(args[0], "Mirror: point", pos)?;
        let normal = vec3(args[1], "Mirror: normal", pos)?;
        if normal.length() == 0.0 {
            return fail(pos, "Mirror: normal must not be (0, 0, 0)");
        }
        return Ok((point, normal.normalize()));
    }
    let p: Vec<DVec3> = (0..3)
        .map(|i| vec3(args[i], &format!("Mirror: p{i}"), pos))
        .collect::<RResult<_>>()?;
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let scale = (p[1] - p[0]).length().max((p[2] - p[0]).length());
    if n.length() <= 1e-12 * scale * scale || scale == 0.0 {
        return fail(
            pos,
            "Mirror: p0, p1 and p2 are collinear: they span no plane",
        );
    }
    Ok((p[0], n.normalize()))
}

fn register_mirror(engine: &mut Engine) {
    // Every form ends in an optional child; the rest name the plane.
    let mirror = |c: &Ctx, args: &[&Dynamic]| -> RResult<Node> {
        let pos = c.call_position();
        let (plane, child) = match args.last() {
            Some(v) if v.is::<Node>() => (&args[..args.len() - 1], Some(*v)),
            _ => (args, None),
        };
        let (point, normal) = match plane {
            [] => (DVec3::ZERO, DVec3::X),
            [axis] => axis_plane(axis, 0.0, pos)?,
            [axis, off] if axis.is_string() => {
                axis_plane(axis, finite(off, "Mirror: offset", pos)?, pos)?
            }
            _ => vector_plane(plane, pos)?,
        };
        Ok(mk(
            NodeKind::Mirror {
                point,
                normal,
                child: optional_child(child, "Mirror: child", pos)?,
            },
            pos,
        ))
    };
    engine.register_fn("Mirror", move |c: Ctx| mirror(&c, &[]));
    engine.register_fn("Mirror", move |c: Ctx, a: Dynamic| mirror(&c, &[&a]));
    engine.register_fn("Mirror", move |c: Ctx, a: Dynamic, b: Dynamic| {
        mirror(&c, &[&a, &b])
    });
    engine.register_fn(
        "Mirror",
        move |c: Ctx, a: Dynamic, b: Dynamic, d: Dynamic| mirror(&c, &[&a, &b, &d]),
    );
    engine.register_fn(
        "Mirror",
        move |c: Ctx, a: Dynamic, b: Dynamic, d: Dynamic, e: Dynamic| mirror(&c, &[&a, &b, &d, &e]),
    );
}

fn register_identity_sum(engine: &mut Engine) {
    register_empty(engine, "Identity", || NodeKind::Identity { child: None });
    engine.register_fn("Identity", |c: Ctx, ch: Dynamic| -> RResult<Node> {
        let p = c.call_position();
        Ok(mk(
            NodeKind::Identity {
                child: Some(node(&ch, "Identity: child", p)?),
            },
            p,
        ))
    });
    let sum = |c: &Ctx, iso: Option<&Dynamic>, ch: Option<&Dynamic>| -> RResult<Node> {
        let p = c.call_position();
        Ok(mk(
            NodeKind::Sum {
                iso: iso.map_or(Ok(0.0), |v| finite(v, "Sum: iso_value", p))?,
                children: ch.map_or(Ok(Vec::new()), |v| nodes(v, "Sum: children", p))?,
            },
            p,
        ))
    };
    engine.register_fn("Sum", move |c: Ctx| sum(&c, None, None));
    engine.register_fn("Sum", move |c: Ctx, iso: Dynamic| sum(&c, Some(&iso), None));
    engine.register_fn("Sum", move |c: Ctx, iso: Dynamic, ch: Dynamic| {
        sum(&c, Some(&iso), Some(&ch))
    });
}

/// The tapered Strut from its 4 to 7 arguments (see `register_tapered_strut`).
pub(super) fn tapered(c: &Ctx, args: &[&Dynamic]) -> RResult<Node> {
    let p = c.call_position();
    let (a, b) = (
        vec3(args[0], "Strut: start", p)?,
        vec3(args[1], "Strut: end", p)?,
    );
    let radius_a = positive(args[2], "Strut: start_radius", p)?;
    let radius_b = positive(args[3], "Strut: end_radius", p)?;
    let mut caps = [CapMode::Sphere; 2];
    let mut m = 1;
    let mut extra = &args[4..];
    // A trailing integer (or a third extra argument) is the material.
    if let Some(last) = extra.last()
        && (last.is_int() || extra.len() == 3)
    {
        m = material(last, p)?;
        extra = &extra[..extra.len() - 1];
    }
    for (i, v) in extra.iter().enumerate() {
        caps[i] = cap_mode(v, ["Strut: start_cap", "Strut: end_cap"][i], p)?;
    }
    if a == b && (radius_a != radius_b || caps.contains(&CapMode::Butt)) {
        return fail(
            p,
            "Strut: start and end are the same point; a tapered or flat-ended strut needs a length",
        );
    }
    Ok(mk(
        NodeKind::TaperedStrut {
            a,
            b,
            radius_a,
            radius_b,
            cap_a: caps[0],
            cap_b: caps[1],
            material: m,
        },
        p,
    ))
}
