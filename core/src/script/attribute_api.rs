//! Script functions of property fields (pyvcad 3's attributes):
//! `node.set_attribute(name, value)`, `node.set_attribute(name, field,
//! column)`, `node.set_attribute_conflict_resolver(name, resolver)` and the
//! `Vec4(r, g, b, a)` value. See [`crate::attribute`].

use glam::DVec4;
use rhai::{Dynamic, Engine, NativeCallContext as Ctx, Position};

use super::values::*;
use crate::attribute::{
    AttrDef, AttrSource, AttributeKind, Component, ConvMap, Resolver, Table, check_kind,
};
use crate::expr::COORD_VARS;
use crate::node::{Node, NodeKind};

/// `Vec4(r, g, b, a)` in scripts (an RGBA colour in 0-1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vec4(pub DVec4);

pub(super) fn register(engine: &mut Engine, ctx: &super::RunContext) {
    register_convert(engine, ctx);
    register_mix(engine);
    engine.register_type_with_name::<Vec4>("Vec4");
    engine.register_fn(
        "Vec4",
        |c: Ctx, x: Dynamic, y: Dynamic, z: Dynamic, w: Dynamic| -> RResult<Vec4> {
            let p = c.call_position();
            Ok(Vec4(DVec4::new(
                finite(&x, "Vec4: r", p)?,
                finite(&y, "Vec4: g", p)?,
                finite(&z, "Vec4: b", p)?,
                finite(&w, "Vec4: a", p)?,
            )))
        },
    );
    engine.register_get("r", |v: &mut Vec4| v.0.x);
    engine.register_get("g", |v: &mut Vec4| v.0.y);
    engine.register_get("b", |v: &mut Vec4| v.0.z);
    engine.register_get("a", |v: &mut Vec4| v.0.w);
    engine.register_fn("to_string", |a: &mut Vec4| {
        format!("Vec4({}, {}, {}, {})", a.0.x, a.0.y, a.0.z, a.0.w)
    });
    engine.register_fn(
        "set_attribute",
        |c: Ctx, n: &mut Node, name: &str, v: Dynamic| -> RResult<()> {
            let p = c.call_position();
            let def = value_def(name, &v, p)?;
            n.attributes_mut().set(def);
            Ok(())
        },
    );
    engine.register_fn(
        "set_attribute",
        |c: Ctx, n: &mut Node, name: &str, field: Node, column: &str| -> RResult<()> {
            let p = c.call_position();
            let def = data_def(name, &field, column, p)?;
            n.attributes_mut().set(def);
            Ok(())
        },
    );
    engine.register_fn(
        "set_attribute_conflict_resolver",
        |c: Ctx, n: &mut Node, name: &str, r: &str| -> RResult<()> {
            let p = c.call_position();
            check_name(name, p)?;
            let r = Resolver::parse(r).or_else(|m| {
                fail(p, format!("set_attribute_conflict_resolver(\"{name}\"): {m}"))
            })?;
            if !matches!(
                n.kind(),
                NodeKind::Union { .. } | NodeKind::Intersection { .. } | NodeKind::Sum { .. }
            ) {
                return fail(
                    p,
                    format!(
                        "set_attribute_conflict_resolver is for Union, Intersection and Sum (where children overlap), not {}",
                        n.kind().type_name()
                    ),
                );
            }
            n.attributes_mut().set_resolver(name, r, origin(p));
            Ok(())
        },
    );
}

/// `node.set_attribute(name, value)` for a value that carries its own
/// source (an image, a points column): check the name and that `kind`
/// agrees with the attribute's declared kind (`hint` is appended to that
/// refusal), then set it.
pub(super) fn set_sourced(
    n: &mut Node,
    name: &str,
    kind: AttributeKind,
    source: AttrSource,
    p: Position,
    hint: &str,
) -> RResult<()> {
    let what = format!("set_attribute(\"{name}\")");
    check_name(name, p)?;
    check_kind(name, kind, &what).or_else(|e| fail(p, format!("{e}{hint}")))?;
    n.attributes_mut().set(AttrDef {
        name: name.to_owned(),
        kind,
        source,
        origin: origin(p),
    });
    Ok(())
}

/// Refuse names a math string could not tell from a coordinate.
pub(super) fn check_name(name: &str, p: Position) -> RResult<()> {
    if name.trim().is_empty() {
        return fail(
            p,
            "set_attribute: the name is empty; give one such as \"modulus\"",
        );
    }
    if name == crate::attribute::FRACTIONS {
        return fail(
            p,
            "\"fractions\" names the material fractions (FGrade sets them); choose another name",
        );
    }
    if COORD_VARS.iter().any(|v| v.eq_ignore_ascii_case(name)) {
        return fail(
            p,
            format!(
                "set_attribute: \"{name}\" is a coordinate variable of math strings ({}); choose another name",
                COORD_VARS.join(" ")
            ),
        );
    }
    Ok(())
}

/// A component: a number or a math string.
fn component(v: &Dynamic, what: &str, p: Position) -> RResult<Component> {
    if let Ok(s) = v.clone().into_string() {
        return Ok(Component::Text(s));
    }
    Ok(Component::Const(finite(v, what, p)?))
}

fn value_def(name: &str, v: &Dynamic, p: Position) -> RResult<AttrDef> {
    check_name(name, p)?;
    let what = format!("set_attribute(\"{name}\")");
    let comps = if let Some(a) = v.clone().try_cast::<Vec3>() {
        a.0.to_array().map(Component::Const).to_vec()
    } else if let Some(a) = v.clone().try_cast::<Vec4>() {
        a.0.to_array().map(Component::Const).to_vec()
    } else if let Some(arr) = v.clone().try_cast::<rhai::Array>() {
        if arr.len() != 3 && arr.len() != 4 {
            return fail(
                p,
                format!(
                    "{what}: an array value has 3 (Vec3) or 4 (Vec4) numbers or math strings, got {}",
                    arr.len()
                ),
            );
        }
        arr.iter()
            .enumerate()
            .map(|(i, c)| component(c, &format!("{what}: component {}", i + 1), p))
            .collect::<RResult<Vec<_>>>()?
    } else if v.is_string() || v.is_float() || v.is_int() {
        vec![component(v, &what, p)?]
    } else {
        return fail(
            p,
            format!(
                "{what}: the value must be a number, a math string, a Vec3, a Vec4, an array of 3 or 4, or a SimulationField and a column name; got {}",
                described(v)
            ),
        );
    };
    let kind = match comps.len() {
        1 => AttributeKind::Scalar,
        3 => AttributeKind::Vec3,
        _ => AttributeKind::Vec4,
    };
    check_kind(name, kind, &what).or_else(|e| fail(p, e.to_string()))?;
    if let Some((lo, hi, unit)) = crate::attribute::range(name) {
        for c in &comps {
            if let Component::Const(x) = c
                && (*x < lo || *x > hi)
            {
                return fail(
                    p,
                    format!(
                        "{what}: {x} is out of range; it must be {}",
                        crate::attribute::range_text(lo, hi, unit)
                    ),
                );
            }
        }
    }
    Ok(AttrDef {
        name: name.to_owned(),
        kind,
        source: AttrSource::Components(comps),
        origin: origin(p),
    })
}

fn data_def(name: &str, field: &Node, column: &str, p: Position) -> RResult<AttrDef> {
    check_name(name, p)?;
    let what = format!("set_attribute(\"{name}\")");
    let NodeKind::SimulationField { field, .. } = field.kind() else {
        return fail(
            p,
            format!(
                "{what}: data comes from a SimulationField node and a column name, got a {}",
                field.kind().type_name()
            ),
        );
    };
    let names = field.variable_names();
    let Some(col) = names.iter().position(|c| c == column) else {
        return fail(
            p,
            format!(
                "{what}: the field has no column \"{column}\"; it has {}",
                names.join(", ")
            ),
        );
    };
    check_kind(name, AttributeKind::Scalar, &what).or_else(|e| fail(p, e.to_string()))?;
    Ok(AttrDef {
        name: name.to_owned(),
        kind: AttributeKind::Scalar,
        source: AttrSource::Data {
            field: field.clone(),
            column: col,
            column_name: column.to_owned(),
        },
        origin: origin(p),
    })
}

/// `Convert(child, from, to, table)`: `to` from `from` through a table
/// (an array of `[input, output]` pairs or a `.csv` file of two columns)
/// or a math string of the coordinates and `from`.
fn register_convert(engine: &mut Engine, ctx: &super::RunContext) {
    let c = ctx.clone();
    engine.register_fn(
        "Convert",
        move |cc: Ctx, child: Node, from: &str, to: &str, map: Dynamic| -> RResult<Node> {
            let p = cc.call_position();
            if from == crate::attribute::FRACTIONS {
                return fail(p, format!("Convert(\"fractions\" -> \"{to}\"): give a mixing rule and one value per material: Convert(child, \"fractions\", \"{to}\", \"voigt\", [[m.id(\"a\"), 2000], [m.id(\"b\"), 1]])"));
            }
            check_name(from, p)?;
            check_name(to, p)?;
            let what = format!("Convert(\"{from}\" -> \"{to}\")");
            if from == to {
                return fail(p, format!("{what}: converts an attribute to itself; name another target"));
            }
            check_kind(to, AttributeKind::Scalar, &what).or_else(|e| fail(p, e.to_string()))?;
            let map = if let Some(rows) = map.clone().try_cast::<rhai::Array>() {
                let pairs = rows
                    .iter()
                    .enumerate()
                    .map(|(i, r)| {
                        let row = format!("{what}: table row {}", i + 1);
                        match r.clone().try_cast::<rhai::Array>() {
                            Some(v) if v.len() == 2 => Ok((finite(&v[0], &row, p)?, finite(&v[1], &row, p)?)),
                            _ => fail(p, format!("{row} must be a pair [input, output], got {}", described(r))),
                        }
                    })
                    .collect::<RResult<Vec<_>>>()?;
                ConvMap::Table(std::sync::Arc::new(Table::new(&pairs, &what).or_else(|m| fail(p, m))?))
            } else if let Ok(s) = map.clone().into_string() {
                if s.to_ascii_lowercase().ends_with(".csv") {
                    let full = c.resolve(&s, p)?;
                    let text = std::fs::read_to_string(&full)
                        .or_else(|e| fail(p, format!("{what}: {}: {e}", full.display())))?;
                    let t = Table::parse_csv(&text, &full.display().to_string()).or_else(|m| fail(p, format!("{what}: {m}")))?;
                    ConvMap::Table(std::sync::Arc::new(t))
                } else {
                    ConvMap::Expr(s)
                }
            } else {
                return fail(p, format!("{what}: the conversion is an array of [input, output] pairs, a .csv table or a math string of \"{from}\"; got {}", described(&map)));
            };
            let mut n = Node::with_origin(NodeKind::Identity { child: Some(child) }, origin(p));
            n.attributes_mut().set(AttrDef {
                name: to.to_owned(),
                kind: AttributeKind::Scalar,
                source: AttrSource::Convert { from: from.to_owned(), map },
                origin: origin(p),
            });
            Ok(n)
        },
    );
}

/// `Convert(child, "fractions", to, "voigt" | "reuss", [[id, value], ...])`:
/// `to` from the child's material fractions by a mixing rule.
fn register_mix(engine: &mut Engine) {
    engine.register_fn(
        "Convert",
        |cc: Ctx, child: Node, from: &str, to: &str, rule: &str, values: rhai::Array| -> RResult<Node> {
            let p = cc.call_position();
            check_name(to, p)?;
            let what = format!("Convert(\"{from}\" -> \"{to}\")");
            if from != crate::attribute::FRACTIONS {
                return fail(p, format!("{what}: a mixing rule converts \"fractions\"; for an attribute give a table or a math string: Convert(child, \"{from}\", \"{to}\", table)"));
            }
            check_kind(to, AttributeKind::Scalar, &what).or_else(|e| fail(p, e.to_string()))?;
            let reuss = match rule.to_ascii_lowercase().as_str() {
                "voigt" => false,
                "reuss" => true,
                _ => return fail(p, format!("{what}: the rule is \"voigt\" (parallel, Σ f·v) or \"reuss\" (series, 1/Σ f/v), got {rule:?}")),
            };
            let mut pairs = Vec::with_capacity(values.len());
            for (i, r) in values.iter().enumerate() {
                let row = format!("{what}: value {}", i + 1);
                let Some(v) = r.clone().try_cast::<rhai::Array>().filter(|v| v.len() == 2) else {
                    return fail(p, format!("{row} must be a pair [material id, value], got {}", described(r)));
                };
                let id = material(&v[0], p)?;
                let x = finite(&v[1], &row, p)?;
                if reuss && x <= 0.0 {
                    return fail(p, format!("{row}: {x}; Reuss's rule divides by each value, so each must be above 0"));
                }
                pairs.push((id, x));
            }
            if pairs.is_empty() {
                return fail(p, format!("{what}: give at least one [material id, value] pair"));
            }
            let mut n = Node::with_origin(NodeKind::Identity { child: Some(child) }, origin(p));
            n.attributes_mut().set(AttrDef {
                name: to.to_owned(),
                kind: AttributeKind::Scalar,
                source: AttrSource::Convert { from: from.to_owned(), map: ConvMap::Mix { reuss, values: pairs } },
                origin: origin(p),
            });
            Ok(n)
        },
    );
}
