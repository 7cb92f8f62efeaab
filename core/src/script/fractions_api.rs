//! Script functions of the scalar -> fractions conversion:
//! `fractions([m.id("a"), m.id("b")])` names the materials a conversion
//! mixes, and `Convert(child, from, fractions([...]), table)` gives the
//! child the mix whose measured `from` is the target (see
//! [`crate::attribute::MixTable`]).

use std::sync::Arc;

use rhai::{Dynamic, Engine, NativeCallContext as Ctx, Position};

use super::values::*;
use crate::attribute::{FracConv, MixTable};
use crate::material::MaterialId;
use crate::node::{Node, NodeKind};

/// `fractions([a, b])` in scripts: the materials a conversion to
/// fractions mixes (the mix table's share is the second's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FractionsTarget(pub [MaterialId; 2]);

pub(super) fn register(engine: &mut Engine, ctx: &super::RunContext) {
    engine.register_type_with_name::<FractionsTarget>("Fractions");
    engine.register_fn(
        "fractions",
        |c: Ctx, ids: rhai::Array| -> RResult<FractionsTarget> {
            let p = c.call_position();
            if ids.len() != 2 {
                return fail(
                    p,
                    format!(
                        "fractions: a mix table mixes 2 materials, got {}; write fractions([m.id(\"a\"), m.id(\"b\")])",
                        ids.len()
                    ),
                );
            }
            let (a, b) = (material(&ids[0], p)?, material(&ids[1], p)?);
            if a == b {
                return fail(p, format!("fractions: both materials are {a}; name two different materials"));
            }
            Ok(FractionsTarget([a, b]))
        },
    );
    engine.register_fn("to_string", |f: &mut FractionsTarget| {
        format!("fractions([{}, {}])", f.0[0], f.0[1])
    });
    let c = ctx.clone();
    engine.register_fn(
        "Convert",
        move |cc: Ctx, child: Node, from: &str, to: FractionsTarget, table: Dynamic| -> RResult<Node> {
            let p = cc.call_position();
            if from == crate::attribute::FRACTIONS || from.trim().is_empty() {
                return fail(p, format!("Convert(\"{from}\" -> fractions): name the number attribute to convert, such as \"shore_hardness\""));
            }
            let what = format!("Convert(\"{from}\" -> fractions)");
            let table = mix_table(&c, &what, &table, p)?;
            let mut n = Node::with_origin(NodeKind::Identity { child: Some(child) }, origin(p));
            n.attributes_mut().to_fractions = Some(FracConv {
                from: from.to_owned(),
                materials: to.0,
                table: Arc::new(table),
                origin: origin(p),
            });
            Ok(n)
        },
    );
}

/// A mix table from `[[share, value], ...]` or a `.csv` file of two
/// columns.
fn mix_table(c: &super::RunContext, what: &str, table: &Dynamic, p: Position) -> RResult<MixTable> {
    if let Some(rows) = table.clone().try_cast::<rhai::Array>() {
        let mut pairs = Vec::with_capacity(rows.len());
        for (i, r) in rows.iter().enumerate() {
            let row = format!("{what}: table row {}", i + 1);
            match r.clone().try_cast::<rhai::Array>() {
                Some(v) if v.len() == 2 => {
                    pairs.push((finite(&v[0], &row, p)?, finite(&v[1], &row, p)?))
                }
                _ => {
                    return fail(
                        p,
                        format!(
                            "{row} must be a pair [share of the second material, value], got {}",
                            described(r)
                        ),
                    );
                }
            }
        }
        return MixTable::new(&pairs, what).or_else(|m| fail(p, m));
    }
    match table.clone().into_string() {
        Ok(s) if s.to_ascii_lowercase().ends_with(".csv") => {
            let full = c.resolve(&s, p)?;
            let text = std::fs::read_to_string(&full)
                .or_else(|e| fail(p, format!("{what}: {}: {e}", full.display())))?;
            MixTable::parse_csv(&text, &full.display().to_string())
                .or_else(|m| fail(p, format!("{what}: {m}")))
        }
        _ => fail(
            p,
            format!(
                "{what}: the mix table is an array of [share of the second material, value] rows or a .csv file of them; got {}",
                described(table)
            ),
        ),
    }
}
