//! pyvcad's node queries, so scripts that print values port:
//! `node.evaluate(x, y, z)` (the signed distance), `node.distribution(x, y,
//! z)` (material fractions), `node.bounding_box()` and `node.prepare(...)`;
//! and pyvcad's `BBoxUnion` (with `BBoxIntersection` beside it) as names
//! of `Union` and `Intersection`.
//!
//! Each query prepares the node as a model with the table the script has
//! chosen so far, so it answers for the tree as it is at that line; pyvcad
//! needs `prepare` first, here it is accepted and does nothing.

use std::sync::Arc;

use glam::DVec3;
use rhai::{Dynamic, Engine, NativeCallContext as Ctx};

use super::RunContext;
use super::nodes_api::mk;
use super::values::*;
use crate::Model;
use crate::material::MaterialTable;
use crate::node::{Node, NodeKind};

/// The node prepared with the script's current table.
fn model(ctx: &RunContext, n: &Node, what: &str, c: &Ctx) -> RResult<Model> {
    let table = ctx
        .lock()
        .table
        .clone()
        .unwrap_or_else(|| Arc::new(MaterialTable::default_table()));
    Model::prepare(n, table).or_else(|e| fail(c.call_position(), format!("{what}: {e}")))
}

fn point(x: &Dynamic, y: &Dynamic, z: &Dynamic, what: &str, c: &Ctx) -> RResult<DVec3> {
    let p = c.call_position();
    Ok(DVec3::new(
        finite(x, &format!("{what}: x"), p)?,
        finite(y, &format!("{what}: y"), p)?,
        finite(z, &format!("{what}: z"), p)?,
    ))
}

/// Register the queries and the BBox names.
pub(super) fn register(engine: &mut Engine, ctx: &RunContext) {
    let c1 = ctx.clone();
    engine.register_fn(
        "evaluate",
        move |c: Ctx, n: &mut Node, x: Dynamic, y: Dynamic, z: Dynamic| -> RResult<f64> {
            let p = point(&x, &y, &z, "evaluate", &c)?;
            Ok(model(&c1, n, "evaluate", &c)?.distance(p))
        },
    );
    // pyvcad returns {id: fraction}; an array indexed by material id reads
    // the same way (`d[id]`), with 0 for the materials absent there.
    let c2 = ctx.clone();
    engine.register_fn(
        "distribution",
        move |c: Ctx, n: &mut Node, x: Dynamic, y: Dynamic, z: Dynamic| -> RResult<rhai::Array> {
            let p = point(&x, &y, &z, "distribution", &c)?;
            let m = model(&c2, n, "distribution", &c)?;
            let (_, fracs) = m.eval_point(p);
            let top = fracs
                .iter()
                .map(|(id, _)| *id as usize + 1)
                .max()
                .unwrap_or(0);
            let mut out = vec![Dynamic::from_float(0.0); m.table().len().max(top)];
            for (id, f) in fracs {
                out[id as usize] = Dynamic::from_float(f);
            }
            Ok(out)
        },
    );
    let c3 = ctx.clone();
    engine.register_fn(
        "bounding_box",
        move |c: Ctx, n: &mut Node| -> RResult<rhai::Array> {
            let b = model(&c3, n, "bounding_box", &c)?.bbox();
            Ok(vec![Dynamic::from(Vec3(b.min)), Dynamic::from(Vec3(b.max))])
        },
    );
    engine.register_fn(
        "prepare",
        |c: Ctx, _n: &mut Node, voxel: Dynamic, inner: Dynamic, outer: Dynamic| -> RResult<()> {
            let p = c.call_position();
            vec3(&voxel, "prepare: voxel_size", p)?;
            finite(&inner, "prepare: interior_bandwidth", p)?;
            finite(&outer, "prepare: exterior_bandwidth", p)?;
            Ok(())
        },
    );
    engine.register_fn("prepare", |_n: &mut Node| ());

    type Make = fn(Vec<Node>) -> NodeKind;
    let union: Make = |children| NodeKind::Union {
        smooth: 0.0,
        blend: false,
        children,
    };
    let inter: Make = |children| NodeKind::Intersection {
        smooth: 0.0,
        blend: false,
        children,
    };
    for (name, make) in [("BBoxUnion", union), ("BBoxIntersection", inter)] {
        engine.register_fn(name, move |c: Ctx| mk(make(vec![]), c.call_position()));
        engine.register_fn(name, move |c: Ctx, ch: Dynamic| -> RResult<Node> {
            let p = c.call_position();
            Ok(mk(make(nodes(&ch, &format!("{name}: children"), p)?), p))
        });
    }
}
