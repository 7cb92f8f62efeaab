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

    register_mesh(engine, ctx);

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

/// `Mesh(path)`, `Mesh(path, m)`, `Mesh(path, m, disable_validation)`,
/// `Mesh(path, sample_size)`, `Mesh(path, sample_size, m)` and
/// `Mesh(path, sample_size, m, disable_validation)`: pyvcad 2.3.4's two
/// constructors (pyvcad 2.3.4). `sample_size` is checked and otherwise
/// not needed: distances come from the triangles exactly, not from a grid.
fn register_mesh(engine: &mut Engine, ctx: &RunContext) {
    let c = ctx.clone();
    let mesh = move |cc: &Ctx, path: &str, args: &[&Dynamic]| -> RResult<Node> {
        let p = cc.call_position();
        let form = MeshArgs::parse(args, p)?;
        let full = c.resolve(path, p)?;
        let mesh = file_cache::cached(&[&full], || crate::trimesh::TriangleMesh::load(&full))
            .or_else(|e| fail(p, e.to_string()))?;
        if form.validate {
            // Named as the script wrote it, so the suggested call is one to paste.
            mesh.check_closed(std::path::Path::new(path))
                .or_else(|e| fail(p, e.to_string()))?;
        }
        {
            let mut st = c.lock();
            for w in mesh.warnings() {
                st.warnings.push(format!("Mesh(\"{path}\"): {w}"));
            }
        }
        Ok(Node::with_origin(
            NodeKind::Mesh {
                mesh,
                material: form.material,
            },
            origin(p),
        ))
    };
    let (m1, m2, m3) = (mesh.clone(), mesh.clone(), mesh.clone());
    engine.register_fn("Mesh", move |cc: Ctx, path: &str| m1(&cc, path, &[]));
    engine.register_fn("Mesh", move |cc: Ctx, path: &str, a: Dynamic| {
        m2(&cc, path, &[&a])
    });
    engine.register_fn(
        "Mesh",
        move |cc: Ctx, path: &str, a: Dynamic, b: Dynamic| m3(&cc, path, &[&a, &b]),
    );
    engine.register_fn(
        "Mesh",
        move |cc: Ctx, path: &str, a: Dynamic, b: Dynamic, d: Dynamic| {
            mesh(&cc, path, &[&a, &b, &d])
        },
    );
}

/// The arguments after a `Mesh` path.
struct MeshArgs {
    material: u8,
    validate: bool,
}

impl MeshArgs {
    const FORMS: &str = "Mesh(path), Mesh(path, m), Mesh(path, m, disable_validation) or Mesh(path, Vec3 sample_size, m, disable_validation)";

    fn parse(args: &[&Dynamic], p: rhai::Position) -> RResult<MeshArgs> {
        // The second form starts with a Vec3 sample size.
        let rest = match args.first() {
            Some(a) if a.is::<Vec3>() => {
                let s = vec3(a, "Mesh: sample_size (argument 2)", p)?;
                if !(s.is_finite() && s.min_element() > 0.0) {
                    return fail(
                        p,
                        format!(
                            "Mesh: sample_size (argument 2) must be positive in x, y and z, got Vec3({}, {}, {})",
                            s.x, s.y, s.z
                        ),
                    );
                }
                &args[1..]
            }
            _ if args.len() == 3 => {
                return fail(
                    p,
                    format!(
                        "Mesh: with 4 arguments the second is the sample size, a Vec3; got {}. Write {}",
                        described(args[0]),
                        Self::FORMS
                    ),
                );
            }
            _ => args,
        };
        let first = args.len() - rest.len() + 2; // 1-based position of rest[0]
        let material = match rest.first() {
            None => 1,
            Some(m) => material(m, p).map_err(|e| match *e {
                rhai::EvalAltResult::ErrorRuntime(msg, pos) => {
                    Box::new(rhai::EvalAltResult::ErrorRuntime(
                        format!("Mesh: argument {first} (the material): {msg}").into(),
                        pos,
                    ))
                }
                other => Box::new(other),
            })?,
        };
        let validate = match rest.get(1) {
            None => true,
            Some(d) => !d.as_bool().or_else(|_| {
                fail(
                    p,
                    format!(
                        "Mesh: argument {} is disable_validation and must be true or false, got {}",
                        first + 1,
                        described(d)
                    ),
                )
            })?,
        };
        Ok(MeshArgs { material, validate })
    }
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
