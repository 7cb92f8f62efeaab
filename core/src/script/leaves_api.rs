//! Leaf constructors scripts call (primitives, lattices, TPMS, meshes,
//! simulation fields), with pyvcad 2.x names and argument orders; the
//! shared argument helpers are in `nodes_api`.

use glam::DVec3;
use rhai::{Dynamic, Engine, NativeCallContext as Ctx};

use super::nodes_api::{compile, mk, register_empty};
use super::values::*;
use crate::expr::COORD_VARS;
use crate::lattice::unit_cell_edges;
use crate::node::{LatticeType, Node, NodeKind, TpmsType};

/// Register leaf constructors.
pub fn register_leaves(engine: &mut Engine) {
    register_sphere_and_box(engine);
    register_cylinder_and_strut(engine);
    register_extrude_and_function(engine);
    register_tpms_and_lattice(engine);
}

/// `Sphere` and `RectPrism`.
fn register_sphere_and_box(engine: &mut Engine) {
    // Sphere
    register_empty(engine, "Sphere", || NodeKind::Sphere {
        center: DVec3::ZERO,
        radius: 1.0,
        material: 1,
    });
    let sphere = |c: &Ctx, center: &Dynamic, r: &Dynamic, m: Option<&Dynamic>| -> RResult<Node> {
        let p = c.call_position();
        Ok(mk(
            NodeKind::Sphere {
                center: vec3(center, "Sphere: center", p)?,
                radius: positive(r, "Sphere: radius", p)?,
                material: m.map_or(Ok(1), |m| material(m, p))?,
            },
            p,
        ))
    };
    register_optional_last!(engine, "Sphere", sphere(a, r; m));
    engine.register_fn(
        "Sphere",
        move |c: Ctx,
              x: Dynamic,
              y: Dynamic,
              z: Dynamic,
              r: Dynamic,
              m: Dynamic|
              -> RResult<Node> {
            let p = c.call_position();
            let center = DVec3::new(
                finite(&x, "Sphere: cx", p)?,
                finite(&y, "Sphere: cy", p)?,
                finite(&z, "Sphere: cz", p)?,
            );
            sphere(&c, &Dynamic::from(Vec3(center)), &r, Some(&m))
        },
    );

    // RectPrism
    register_empty(engine, "RectPrism", || NodeKind::RectPrism {
        center: DVec3::ZERO,
        size: DVec3::ONE,
        material: 1,
    });
    let prism = |c: &Ctx, center: &Dynamic, size: &Dynamic, m: Option<&Dynamic>| -> RResult<Node> {
        let p = c.call_position();
        let size = vec3(size, "RectPrism: size", p)?;
        if size.min_element() <= 0.0 {
            return fail(
                p,
                format!(
                    "RectPrism: size must be > 0 on every axis, got ({}, {}, {})",
                    size.x, size.y, size.z
                ),
            );
        }
        Ok(mk(
            NodeKind::RectPrism {
                center: vec3(center, "RectPrism: center", p)?,
                size,
                material: m.map_or(Ok(1), |m| material(m, p))?,
            },
            p,
        ))
    };
    register_optional_last!(engine, "RectPrism", prism(a, s; m));
}

/// `Cylinder` and `Strut` (pyvcad 3's tapered strut is in `shapes_api`).
fn register_cylinder_and_strut(engine: &mut Engine) {
    // Cylinder
    register_empty(engine, "Cylinder", || NodeKind::Cylinder {
        center: DVec3::ZERO,
        radius: 1.0,
        height: 1.0,
        material: 1,
    });
    let cyl = |c: &Ctx,
               center: &Dynamic,
               r: &Dynamic,
               h: &Dynamic,
               m: Option<&Dynamic>|
     -> RResult<Node> {
        let p = c.call_position();
        Ok(mk(
            NodeKind::Cylinder {
                center: vec3(center, "Cylinder: center", p)?,
                radius: positive(r, "Cylinder: radius", p)?,
                height: positive(h, "Cylinder: height", p)?,
                material: m.map_or(Ok(1), |m| material(m, p))?,
            },
            p,
        ))
    };
    register_optional_last!(engine, "Cylinder", cyl(a, r, h; m));

    // Strut
    let strut =
        |c: &Ctx, a: &Dynamic, b: &Dynamic, r: &Dynamic, m: Option<&Dynamic>| -> RResult<Node> {
            let p = c.call_position();
            Ok(mk(
                NodeKind::Strut {
                    a: vec3(a, "Strut: start", p)?,
                    b: vec3(b, "Strut: end", p)?,
                    radius: positive(r, "Strut: radius", p)?,
                    material: m.map_or(Ok(1), |m| material(m, p))?,
                },
                p,
            ))
        };
    engine.register_fn(
        "Strut",
        move |c: Ctx, a: Dynamic, b: Dynamic, r: Dynamic| strut(&c, &a, &b, &r, None),
    );
    // A fourth argument that is not an integer material id is pyvcad 3's
    // end radius (a tapered strut, `shapes_api`).
    engine.register_fn(
        "Strut",
        move |c: Ctx, a: Dynamic, b: Dynamic, r: Dynamic, m: Dynamic| {
            if m.is_int() {
                strut(&c, &a, &b, &r, Some(&m))
            } else {
                super::shapes_api::tapered(&c, &[&a, &b, &r, &m])
            }
        },
    );
}

/// `PolygonExtrude` and `Function` (an implicit expression).
fn register_extrude_and_function(engine: &mut Engine) {
    // PolygonExtrude
    let poly = |c: &Ctx,
                v: &Dynamic,
                h: &Dynamic,
                sym: Option<&Dynamic>,
                m: Option<&Dynamic>|
     -> RResult<Node> {
        let p = c.call_position();
        let Some(arr) = v.clone().try_cast::<rhai::Array>() else {
            return fail(p, "PolygonExtrude: vertices must be an array of Vec3");
        };
        let vertices = arr
            .iter()
            .enumerate()
            .map(|(i, v)| vec3(v, &format!("PolygonExtrude: vertex {i}"), p))
            .collect::<RResult<Vec<_>>>()?;
        if vertices.len() < 3 {
            return fail(
                p,
                format!(
                    "PolygonExtrude: needs at least 3 vertices, got {}",
                    vertices.len()
                ),
            );
        }
        let height = finite(h, "PolygonExtrude: height", p)?;
        if height == 0.0 {
            return fail(p, "PolygonExtrude: height must not be 0");
        }
        Ok(mk(
            NodeKind::PolygonExtrude {
                vertices,
                height,
                symmetric: sym.map_or(Ok(false), |s| boolean(s, "PolygonExtrude: symmetric", p))?,
                material: m.map_or(Ok(1), |m| material(m, p))?,
            },
            p,
        ))
    };
    engine.register_fn("PolygonExtrude", move |c: Ctx, v: Dynamic, h: Dynamic| {
        poly(&c, &v, &h, None, None)
    });
    engine.register_fn(
        "PolygonExtrude",
        move |c: Ctx, v: Dynamic, h: Dynamic, s: Dynamic| poly(&c, &v, &h, Some(&s), None),
    );
    engine.register_fn(
        "PolygonExtrude",
        move |c: Ctx, v: Dynamic, h: Dynamic, s: Dynamic, m: Dynamic| {
            poly(&c, &v, &h, Some(&s), Some(&m))
        },
    );

    // Function
    let func = |c: &Ctx,
                e: &Dynamic,
                m: Option<&Dynamic>,
                lo: Option<&Dynamic>,
                hi: Option<&Dynamic>|
     -> RResult<Node> {
        let p = c.call_position();
        let Ok(src) = e.clone().into_string() else {
            return fail(
                p,
                "Function: the first argument must be a math string such as \"x*x + y*y - 4\"",
            );
        };
        let expr = compile(&src, &COORD_VARS[..8], "Function", p)?;
        let min = lo.map_or(Ok(DVec3::splat(-10.0)), |v| vec3(v, "Function: min", p))?;
        let max = hi.map_or(Ok(DVec3::splat(10.0)), |v| vec3(v, "Function: max", p))?;
        if min.cmpge(max).any() {
            return fail(p, "Function: min must be below max on every axis");
        }
        Ok(mk(
            NodeKind::Function {
                expr,
                material: m.map_or(Ok(1), |m| material(m, p))?,
                min,
                max,
            },
            p,
        ))
    };
    engine.register_fn("Function", move |c: Ctx, e: Dynamic| {
        func(&c, &e, None, None, None)
    });
    engine.register_fn("Function", move |c: Ctx, e: Dynamic, m: Dynamic| {
        func(&c, &e, Some(&m), None, None)
    });
    engine.register_fn(
        "Function",
        move |c: Ctx, e: Dynamic, m: Dynamic, lo: Dynamic, hi: Dynamic| {
            func(&c, &e, Some(&m), Some(&lo), Some(&hi))
        },
    );
}

/// TPMS sheets and `GraphLattice`.
fn register_tpms_and_lattice(engine: &mut Engine) {
    // TPMS sheets (ours; pyvcad 2.x has none).
    for (name, kind) in [
        ("Gyroid", TpmsType::Gyroid),
        ("SchwarzP", TpmsType::SchwarzP),
        ("Diamond", TpmsType::Diamond),
    ] {
        engine.register_fn(
            name,
            move |c: Ctx, cell: Dynamic, t: Dynamic, m: Dynamic| -> RResult<Node> {
                let p = c.call_position();
                let cell = if cell.is_float() || cell.is_int() {
                    DVec3::splat(positive(&cell, &format!("{name}: cell size"), p)?)
                } else {
                    vec3(&cell, &format!("{name}: cell size"), p)?
                };
                if cell.min_element() <= 0.0 {
                    return fail(p, format!("{name}: cell size must be > 0 on every axis"));
                }
                Ok(mk(
                    NodeKind::Tpms {
                        kind,
                        cell,
                        thickness: positive(&t, &format!("{name}: wall thickness"), p)?,
                        material: material(&m, p)?,
                    },
                    p,
                ))
            },
        );
    }

    // GraphLattice
    engine.register_fn(
        "GraphLattice",
        |c: Ctx, t: LatticeType, cell: Dynamic, r: Dynamic, m: Dynamic| -> RResult<Node> {
            let p = c.call_position();
            let cell = vec3(&cell, "GraphLattice: cell size", p)?;
            if cell.min_element() <= 0.0 {
                return fail(p, "GraphLattice: cell size must be > 0 on every axis");
            }
            Ok(mk(
                NodeKind::GraphLattice {
                    edges: unit_cell_edges(t, cell),
                    cell: Some(cell),
                    radius: positive(&r, "GraphLattice: radius", p)?,
                    material: material(&m, p)?,
                },
                p,
            ))
        },
    );
    engine.register_fn(
        "GraphLattice",
        |c: Ctx, edges: rhai::Array, r: Dynamic, m: Dynamic| -> RResult<Node> {
            let p = c.call_position();
            let mut out = Vec::with_capacity(edges.len());
            for (i, e) in edges.iter().enumerate() {
                let pair = e.clone().try_cast::<rhai::Array>().filter(|a| a.len() == 2);
                let Some(pair) = pair else {
                    return fail(p, format!("GraphLattice: edge {i} must be [Vec3, Vec3]"));
                };
                out.push((
                    vec3(&pair[0], &format!("GraphLattice: edge {i} start"), p)?,
                    vec3(&pair[1], &format!("GraphLattice: edge {i} end"), p)?,
                ));
            }
            if out.is_empty() {
                return fail(p, "GraphLattice: the edge list is empty");
            }
            Ok(mk(
                NodeKind::GraphLattice {
                    edges: out,
                    cell: None,
                    radius: positive(&r, "GraphLattice: radius", p)?,
                    material: material(&m, p)?,
                },
                p,
            ))
        },
    );
}
