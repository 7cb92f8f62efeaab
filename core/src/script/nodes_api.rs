//! The node constructors scripts call, with pyvcad 2.x names and argument
//! orders (pyvcad 2.3.4): transforms, booleans, material nodes and
//! builder methods here, leaves in `leaves_api`. Every constructor checks its arguments
//! and fails at the call's line and column; math strings are compiled here,
//! so an expression's syntax error points at the `FGrade` call that holds it.

use std::sync::Arc;

use glam::DVec3;
use rhai::{Dynamic, Engine, NativeCallContext as Ctx, Position};

use super::values::*;
use crate::expr::{COORD_VARS, Expr};
use crate::node::{Node, NodeKind};

pub(super) fn mk(kind: NodeKind, pos: Position) -> Node {
    Node::with_origin(kind, origin(pos))
}

/// `name()` in scripts: the node `kind` makes, with pyvcad's defaults
/// (children are added later).
pub(super) fn register_empty(engine: &mut Engine, name: &str, kind: fn() -> NodeKind) {
    engine.register_fn(name, move |c: Ctx| -> RResult<Node> {
        Ok(mk(kind(), c.call_position()))
    });
}

pub(super) fn compile(src: &str, vars: &[&str], what: &str, pos: Position) -> RResult<Arc<Expr>> {
    Expr::compile(src, vars)
        .map(Arc::new)
        .or_else(|e| fail(pos, format!("{what}: {e}")))
}

pub(super) fn optional_child(
    v: Option<&Dynamic>,
    what: &str,
    pos: Position,
) -> RResult<Option<Node>> {
    v.map(|v| node(v, what, pos)).transpose()
}

/// Register transforms, booleans and material nodes.
pub fn register_composites(engine: &mut Engine) {
    register_transforms(engine);
    register_union_intersection(engine);
    register_difference(engine);
    register_offset_shell_tile(engine);
    register_grade_blend(engine);
}

/// `Translate`, `Scale` and `Rotate`.
fn register_transforms(engine: &mut Engine) {
    // Translate / Scale: (), (x,y,z), (x,y,z,child)
    type Make = fn(DVec3, Option<Node>) -> NodeKind;
    let translate: Make = |v, child| NodeKind::Translate { offset: v, child };
    let scale: Make = |v, child| NodeKind::Scale { factors: v, child };
    for (name, make, zero) in [
        ("Translate", translate, DVec3::ZERO),
        ("Scale", scale, DVec3::ONE),
    ] {
        let three = move |c: &Ctx,
                          x: &Dynamic,
                          y: &Dynamic,
                          z: &Dynamic,
                          child: Option<&Dynamic>|
              -> RResult<Node> {
            let p = c.call_position();
            let v = DVec3::new(
                finite(x, &format!("{name}: x"), p)?,
                finite(y, &format!("{name}: y"), p)?,
                finite(z, &format!("{name}: z"), p)?,
            );
            if name == "Scale" && v.cmpeq(DVec3::ZERO).any() {
                return fail(p, "Scale: factors must not be 0");
            }
            // Scaling divides the point by the factor: 1/1e-300 overflows.
            if name == "Scale" && v.abs().min_element() < 1.0 / MAX_MAGNITUDE {
                return fail(
                    p,
                    format!("Scale: factors must be at least 1e-9 in magnitude, got {v}"),
                );
            }
            Ok(mk(
                make(v, optional_child(child, &format!("{name}: child"), p)?),
                p,
            ))
        };
        engine.register_fn(name, move |c: Ctx| -> RResult<Node> {
            Ok(mk(make(zero, None), c.call_position()))
        });
        engine.register_fn(name, move |c: Ctx, x: Dynamic, y: Dynamic, z: Dynamic| {
            three(&c, &x, &y, &z, None)
        });
        engine.register_fn(
            name,
            move |c: Ctx, x: Dynamic, y: Dynamic, z: Dynamic, ch: Dynamic| {
                three(&c, &x, &y, &z, Some(&ch))
            },
        );
    }

    // Rotate(pitch, yaw, roll[, around[, child]])
    let rot = |c: &Ctx,
               a: [&Dynamic; 3],
               around: Option<&Dynamic>,
               child: Option<&Dynamic>|
     -> RResult<Node> {
        let p = c.call_position();
        let around = match around {
            None => DVec3::ZERO,
            Some(v) if v.is_int() || v.is_float() => DVec3::splat(finite(v, "Rotate: around", p)?),
            Some(v) => vec3(v, "Rotate: around", p)?,
        };
        Ok(mk(
            NodeKind::Rotate {
                pitch: finite(a[0], "Rotate: pitch", p)?,
                yaw: finite(a[1], "Rotate: yaw", p)?,
                roll: finite(a[2], "Rotate: roll", p)?,
                around,
                child: optional_child(child, "Rotate: child", p)?,
            },
            p,
        ))
    };
    engine.register_fn(
        "Rotate",
        move |c: Ctx, x: Dynamic, y: Dynamic, z: Dynamic| rot(&c, [&x, &y, &z], None, None),
    );
    engine.register_fn(
        "Rotate",
        move |c: Ctx, x: Dynamic, y: Dynamic, z: Dynamic, a: Dynamic| {
            if a.is::<Node>() {
                rot(&c, [&x, &y, &z], None, Some(&a))
            } else {
                rot(&c, [&x, &y, &z], Some(&a), None)
            }
        },
    );
    engine.register_fn(
        "Rotate",
        move |c: Ctx, x: Dynamic, y: Dynamic, z: Dynamic, a: Dynamic, ch: Dynamic| {
            rot(&c, [&x, &y, &z], Some(&a), Some(&ch))
        },
    );
}

/// `Union` and `Intersection`.
fn register_union_intersection(engine: &mut Engine) {
    // Union / Intersection: (), (blend), (blend, children), (k, blend), (k, blend, children)
    type MakeN = fn(f64, bool, Vec<Node>) -> NodeKind;
    let union: MakeN = |smooth, blend, children| NodeKind::Union {
        smooth,
        blend,
        children,
    };
    let inter: MakeN = |smooth, blend, children| NodeKind::Intersection {
        smooth,
        blend,
        children,
    };
    for (name, make) in [("Union", union), ("Intersection", inter)] {
        engine.register_fn(name, move |c: Ctx| -> RResult<Node> {
            Ok(mk(make(0.0, false, vec![]), c.call_position()))
        });
        engine.register_fn(name, move |c: Ctx, b: Dynamic| -> RResult<Node> {
            let p = c.call_position();
            Ok(mk(
                make(
                    0.0,
                    boolean(&b, &format!("{name}: blend materials flag"), p)?,
                    vec![],
                ),
                p,
            ))
        });
        engine.register_fn(
            name,
            move |c: Ctx, a: Dynamic, b: Dynamic| -> RResult<Node> {
                let p = c.call_position();
                if a.is_bool() {
                    Ok(mk(
                        make(
                            0.0,
                            boolean(&a, name, p)?,
                            nodes(&b, &format!("{name}: children"), p)?,
                        ),
                        p,
                    ))
                } else if a.is::<Node>() {
                    // pyvcad's forms take the children as one list.
                    fail(
                        p,
                        format!(
                            "{name} takes (blend, [children]) or (k, blend, [children]): write {name}(false, [a, b]) for two nodes a and b"
                        ),
                    )
                } else {
                    let k = non_negative(&a, &format!("{name}: smoothing radius"), p)?;
                    Ok(mk(
                        make(
                            k,
                            boolean(&b, &format!("{name}: blend materials flag"), p)?,
                            vec![],
                        ),
                        p,
                    ))
                }
            },
        );
        engine.register_fn(
            name,
            move |c: Ctx, k: Dynamic, b: Dynamic, ch: Dynamic| -> RResult<Node> {
                let p = c.call_position();
                Ok(mk(
                    make(
                        non_negative(&k, &format!("{name}: smoothing radius"), p)?,
                        boolean(&b, &format!("{name}: blend materials flag"), p)?,
                        nodes(&ch, &format!("{name}: children"), p)?,
                    ),
                    p,
                ))
            },
        );
    }
}

/// `Difference`.
fn register_difference(engine: &mut Engine) {
    // Difference: (), (L, R), (k), (k, L, R)
    register_empty(engine, "Difference", || NodeKind::Difference {
        smooth: 0.0,
        left: None,
        right: None,
    });
    engine.register_fn("Difference", |c: Ctx, k: Dynamic| -> RResult<Node> {
        let p = c.call_position();
        Ok(mk(
            NodeKind::Difference {
                smooth: non_negative(&k, "Difference: smoothing radius", p)?,
                left: None,
                right: None,
            },
            p,
        ))
    });
    engine.register_fn(
        "Difference",
        |c: Ctx, l: Dynamic, r: Dynamic| -> RResult<Node> {
            let p = c.call_position();
            Ok(mk(
                NodeKind::Difference {
                    smooth: 0.0,
                    left: Some(node(&l, "Difference: left", p)?),
                    right: Some(node(&r, "Difference: right", p)?),
                },
                p,
            ))
        },
    );
    engine.register_fn(
        "Difference",
        |c: Ctx, k: Dynamic, l: Dynamic, r: Dynamic| -> RResult<Node> {
            let p = c.call_position();
            Ok(mk(
                NodeKind::Difference {
                    smooth: non_negative(&k, "Difference: smoothing radius", p)?,
                    left: Some(node(&l, "Difference: left", p)?),
                    right: Some(node(&r, "Difference: right", p)?),
                },
                p,
            ))
        },
    );
}

/// `Offset`, `Shell` and `Tile`.
fn register_offset_shell_tile(engine: &mut Engine) {
    // Offset(o[, child]) and Shell(t[, child]): both signs accepted.
    register_empty(engine, "Offset", || NodeKind::Offset {
        distance: 0.0,
        child: None,
    });
    for arity in [1usize, 2] {
        let off = move |c: &Ctx, o: &Dynamic, ch: Option<&Dynamic>| -> RResult<Node> {
            let p = c.call_position();
            Ok(mk(
                NodeKind::Offset {
                    distance: finite(o, "Offset: distance", p)?,
                    child: optional_child(ch, "Offset: child", p)?,
                },
                p,
            ))
        };
        let shell = move |c: &Ctx, t: &Dynamic, ch: Option<&Dynamic>| -> RResult<Node> {
            let p = c.call_position();
            let t = finite(t, "Shell: thickness", p)?;
            if t == 0.0 {
                return fail(p, "Shell: thickness must not be 0");
            }
            Ok(mk(
                NodeKind::Shell {
                    thickness: t,
                    child: optional_child(ch, "Shell: child", p)?,
                },
                p,
            ))
        };
        if arity == 1 {
            engine.register_fn("Offset", move |c: Ctx, o: Dynamic| off(&c, &o, None));
            engine.register_fn("Shell", move |c: Ctx, t: Dynamic| shell(&c, &t, None));
        } else {
            engine.register_fn("Offset", move |c: Ctx, o: Dynamic, ch: Dynamic| {
                off(&c, &o, Some(&ch))
            });
            engine.register_fn("Shell", move |c: Ctx, t: Dynamic, ch: Dynamic| {
                shell(&c, &t, Some(&ch))
            });
        }
    }

    // Tile: (), (child), (cx, cy, cz), (cx, cy, cz, child)
    register_empty(engine, "Tile", || NodeKind::Tile {
        cell: None,
        child: None,
    });
    engine.register_fn("Tile", |c: Ctx, ch: Dynamic| -> RResult<Node> {
        let p = c.call_position();
        Ok(mk(
            NodeKind::Tile {
                cell: None,
                child: Some(node(&ch, "Tile: child", p)?),
            },
            p,
        ))
    });
    let tile =
        |c: &Ctx, x: &Dynamic, y: &Dynamic, z: &Dynamic, ch: Option<&Dynamic>| -> RResult<Node> {
            let p = c.call_position();
            let cell = DVec3::new(
                positive(x, "Tile: cell x", p)?,
                positive(y, "Tile: cell y", p)?,
                positive(z, "Tile: cell z", p)?,
            );
            Ok(mk(
                NodeKind::Tile {
                    cell: Some(cell),
                    child: optional_child(ch, "Tile: child", p)?,
                },
                p,
            ))
        };
    engine.register_fn("Tile", move |c: Ctx, x: Dynamic, y: Dynamic, z: Dynamic| {
        tile(&c, &x, &y, &z, None)
    });
    engine.register_fn(
        "Tile",
        move |c: Ctx, x: Dynamic, y: Dynamic, z: Dynamic, ch: Dynamic| {
            tile(&c, &x, &y, &z, Some(&ch))
        },
    );
}

/// `FGrade` and `Blend`.
fn register_grade_blend(engine: &mut Engine) {
    // FGrade(exprs, materials, prob[, child])
    let fgrade = |c: &Ctx,
                  e: &Dynamic,
                  m: &Dynamic,
                  prob: &Dynamic,
                  ch: Option<&Dynamic>|
     -> RResult<Node> {
        let p = c.call_position();
        let srcs = strings(e, "FGrade: expressions", p)?;
        let mats = materials(m, "FGrade: materials", p)?;
        if srcs.len() != mats.len() || srcs.is_empty() {
            return fail(
                p,
                format!(
                    "FGrade: {} expressions but {} materials; give one expression per material",
                    srcs.len(),
                    mats.len()
                ),
            );
        }
        let exprs = srcs
            .iter()
            .enumerate()
            .map(|(i, s)| compile(s, &COORD_VARS, &format!("FGrade: expression {}", i + 1), p))
            .collect::<RResult<Vec<_>>>()?;
        Ok(mk(
            NodeKind::FGrade {
                exprs,
                materials: mats,
                prob: boolean(prob, "FGrade: probabilistic flag", p)?,
                child: optional_child(ch, "FGrade: child", p)?,
            },
            p,
        ))
    };
    register_optional_last!(engine, "FGrade", fgrade(e, m, b; ch));

    // Blend(radius[, child])
    let blend = |c: &Ctx, r: &Dynamic, ch: Option<&Dynamic>| -> RResult<Node> {
        let p = c.call_position();
        Ok(mk(
            NodeKind::Blend {
                radius: positive(r, "Blend: radius", p)?,
                child: optional_child(ch, "Blend: child", p)?,
            },
            p,
        ))
    };
    engine.register_fn("Blend", move |c: Ctx, r: Dynamic| blend(&c, &r, None));
    engine.register_fn("Blend", move |c: Ctx, r: Dynamic, ch: Dynamic| {
        blend(&c, &r, Some(&ch))
    });
}

/// Register builder methods: add_child, set_child, set_left, set_right, type.
pub fn register_methods(engine: &mut Engine) {
    engine.register_fn(
        "add_child",
        |c: Ctx, n: &mut Node, child: Node| -> RResult<bool> {
            match n.kind_mut() {
                NodeKind::Union { children, .. }
                | NodeKind::Intersection { children, .. }
                | NodeKind::Sum { children, .. } => {
                    children.push(child);
                    Ok(true)
                }
                k => fail(
                    c.call_position(),
                    format!(
                        "{}: add_child is for Union, Intersection and Sum; use set_child",
                        k.type_name()
                    ),
                ),
            }
        },
    );
    engine.register_fn(
        "set_child",
        |c: Ctx, n: &mut Node, child: Node| -> RResult<()> {
            let name = n.kind().type_name();
            match n.kind_mut().child_slot() {
                Some(slot) => {
                    *slot = Some(child);
                    Ok(())
                }
                None => fail(
                    c.call_position(),
                    format!("{name}: set_child is for single-child nodes"),
                ),
            }
        },
    );
    // pyvcad's Difference takes its two operands one at a time.
    for (name, right) in [("set_left", false), ("set_right", true)] {
        engine.register_fn(
            name,
            move |c: Ctx, n: &mut Node, child: Node| -> RResult<()> {
                match n.kind_mut() {
                    NodeKind::Difference {
                        left: l, right: r, ..
                    } => {
                        *(if right { r } else { l }) = Some(child);
                        Ok(())
                    }
                    k => fail(
                        c.call_position(),
                        format!("{}: {name} is for Difference", k.type_name()),
                    ),
                }
            },
        );
    }
    engine.register_fn("type", |n: &mut Node| n.kind().type_name().to_string());
    engine.register_fn("num_children", |n: &mut Node| {
        n.kind().children().len() as i64
    });
    engine.register_fn("to_string", |n: &mut Node| n.describe());
}
