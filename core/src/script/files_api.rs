//! Script functions that read files beside the script: `read_csv`, `Mesh`,
//! `SimulationField`. Paths resolve in the script's folder and may not leave
//! it (see `RunContext::resolve`).

use std::sync::Arc;

use rhai::{Dynamic, Engine, Map, NativeCallContext as Ctx};

use super::RunContext;
use super::file_cache;
use super::values::*;
use crate::expr::{COORD_VARS, Expr};
use crate::node::{Node, NodeKind};

pub(super) fn register(engine: &mut Engine, ctx: &RunContext) {
    let c = ctx.clone();
    engine.register_fn(
        "read_csv",
        move |cc: Ctx, path: &str| -> RResult<rhai::Array> {
            let p = cc.call_position();
            let full = c.resolve(path, p)?;
            let text = std::fs::read_to_string(&full)
                .or_else(|e| fail(p, format!("{}: {e}", full.display())))?;
            parse_csv(&text).or_else(|m| fail(p, format!("{}: {m}", full.display())))
        },
    );

    let c = ctx.clone();
    let mesh = move |cc: &Ctx, path: &str, m: Option<&Dynamic>| -> RResult<Node> {
        let p = cc.call_position();
        let full = c.resolve(path, p)?;
        let mesh = file_cache::cached(&[&full], || crate::mesh::TriangleMesh::load(&full))
            .or_else(|e| fail(p, e.to_string()))?;
        {
            let mut st = c.lock();
            for w in mesh.warnings() {
                st.warnings.push(format!("Mesh(\"{path}\"): {w}"));
            }
        }
        let material = m.map_or(Ok(1), |m| material(m, p))?;
        Ok(Node::with_origin(
            NodeKind::Mesh { mesh, material },
            origin(p),
        ))
    };
    let m1 = mesh.clone();
    engine.register_fn("Mesh", move |cc: Ctx, path: &str| m1(&cc, path, None));
    engine.register_fn("Mesh", move |cc: Ctx, path: &str, m: Dynamic| {
        mesh(&cc, path, Some(&m))
    });

    let c = ctx.clone();
    engine.register_fn(
        "SimulationField",
        move |cc: Ctx, inp: &str, csv: &str, exprs: Dynamic, mats: Dynamic| -> RResult<Node> {
            let p = cc.call_position();
            let srcs = strings(&exprs, "SimulationField: expressions", p)?;
            let mats = materials(&mats, "SimulationField: materials", p)?;
            if srcs.len() != mats.len() || srcs.is_empty() {
                return fail(p, format!("SimulationField: {} expressions but {} materials; give one expression per material", srcs.len(), mats.len()));
            }
            let inp_path = c.resolve(inp, p)?;
            let csv_path = c.resolve(csv, p)?;
            let field = file_cache::cached(&[&inp_path, &csv_path], || crate::simfield::SimField::load(&inp_path, &csv_path)).or_else(|e| fail(p, e.to_string()))?;
            let names = field.variable_names();
            let mut vars: Vec<&str> = COORD_VARS.to_vec();
            vars.extend(names.iter().map(String::as_str));
            let exprs = srcs
                .iter()
                .enumerate()
                .map(|(i, s)| {
                    Expr::compile(s, &vars).map(Arc::new).or_else(|e| {
                        let mut msg = format!("SimulationField: expression {}: {e}", i + 1);
                        if e.message.starts_with("unknown variable 'len'") {
                            let missing: Vec<&str> = ["dx", "dy", "dz"]
                                .into_iter()
                                .filter(|c| !names.iter().any(|n| n == c))
                                .collect();
                            msg.push_str(&format!(
                                "; `len` is the length of (dx, dy, dz), and {} has no column{} {}",
                                csv_path.display(),
                                if missing.len() > 1 { "s" } else { "" },
                                missing.join(", ")
                            ));
                        }
                        fail(p, msg)
                    })
                })
                .collect::<RResult<Vec<_>>>()?;
            {
                let mut st = c.lock();
                for w in field.warnings() {
                    st.warnings.push(format!("SimulationField: {w}"));
                }
            }
            Ok(Node::with_origin(NodeKind::SimulationField { field, exprs, materials: mats }, origin(p)))
        },
    );
}

/// A CSV with a header row into an array of maps (column name -> value);
/// numeric cells become floats, others strings.
fn parse_csv(text: &str) -> Result<rhai::Array, String> {
    // A UTF-8 byte-order mark (some spreadsheets write one) is not data.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        return Err("the file is empty; expected a header row of column names".into());
    };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let mut rows = rhai::Array::new();
    for (i, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != names.len() {
            return Err(format!(
                "line {}: {} cells, but the header has {} columns",
                i + 1,
                cells.len(),
                names.len()
            ));
        }
        let mut row = Map::new();
        for (n, c) in names.iter().zip(cells) {
            let v = match c.parse::<f64>() {
                Ok(f) => Dynamic::from_float(f),
                Err(_) => Dynamic::from(c.to_owned()),
            };
            row.insert((*n).into(), v);
        }
        rows.push(Dynamic::from_map(row));
    }
    Ok(rows)
}
