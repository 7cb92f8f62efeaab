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

/// `fractions([a, b, ...])` in scripts: the materials a conversion to
/// fractions mixes (two: the mix table's share is the second's; more: the
/// table's rows give each one's fraction).
#[derive(Clone, Debug, PartialEq)]
pub struct FractionsTarget(pub Vec<MaterialId>);

pub(super) fn register(engine: &mut Engine, ctx: &super::RunContext) {
    engine.register_type_with_name::<FractionsTarget>("Fractions");
    engine.register_fn(
        "fractions",
        |c: Ctx, ids: rhai::Array| -> RResult<FractionsTarget> {
            let p = c.call_position();
            if ids.len() < 2 || ids.len() > MAX_MIXED {
                return fail(
                    p,
                    format!(
                        "fractions: a mix table mixes 2 to {MAX_MIXED} materials, got {}; write fractions([m.id(\"a\"), m.id(\"b\")])",
                        ids.len()
                    ),
                );
            }
            let mut mats = Vec::with_capacity(ids.len());
            for v in &ids {
                let m = material(v, p)?;
                if mats.contains(&m) {
                    return fail(p, format!("fractions: material {m} is named twice; name each material once"));
                }
                mats.push(m);
            }
            Ok(FractionsTarget(mats))
        },
    );
    engine.register_fn("to_string", |f: &mut FractionsTarget| {
        let ids: Vec<String> = f.0.iter().map(ToString::to_string).collect();
        format!("fractions([{}])", ids.join(", "))
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
            let table = mix_table(&c, &what, &table, to.0.len(), p)?;
            let mut n = Node::with_origin(NodeKind::Identity { child: Some(child) }, origin(p));
            n.attributes_mut().to_fractions = Some(FracConv {
                from: from.to_owned(),
                materials: to.0.clone(),
                table: Arc::new(table),
                origin: origin(p),
            });
            Ok(n)
        },
    );
}

/// Most materials one conversion mixes.
const MAX_MIXED: usize = 16;

/// A mix table of `n` materials: for two, `[[share, value], ...]` or a
/// `.csv` file of those two columns; for more, rows of the `n` fractions
/// and the value (`[[1, 0, 0, 30], [0, 0.5, 0.5, 60], ...]`, or a `.csv`
/// of `n + 1` columns).
fn mix_table(
    c: &super::RunContext,
    what: &str,
    table: &Dynamic,
    n: usize,
    p: Position,
) -> RResult<MixTable> {
    let shape = if n == 2 {
        "[share of the second material, value]".to_owned()
    } else {
        format!("[the {n} materials' fractions, then the value]")
    };
    if let Some(rows) = table.clone().try_cast::<rhai::Array>() {
        let width = if n == 2 { 2 } else { n + 1 };
        let mut nums = Vec::with_capacity(rows.len());
        for (i, r) in rows.iter().enumerate() {
            let row = format!("{what}: table row {}", i + 1);
            match r.clone().try_cast::<rhai::Array>() {
                Some(v) if v.len() == width => nums.push(
                    v.iter()
                        .map(|x| finite(x, &row, p))
                        .collect::<RResult<Vec<f64>>>()?,
                ),
                _ => {
                    return fail(p, format!("{row} must be {shape}, got {}", described(r)));
                }
            }
        }
        let made = if n == 2 {
            let pairs: Vec<(f64, f64)> = nums.iter().map(|v| (v[0], v[1])).collect();
            MixTable::new(&pairs, what)
        } else {
            MixTable::path(&nums, n, what)
        };
        return made.or_else(|m| fail(p, m));
    }
    match table.clone().into_string() {
        Ok(s) if s.to_ascii_lowercase().ends_with(".csv") => {
            let full = c.resolve(&s, p)?;
            let text = std::fs::read_to_string(&full)
                .or_else(|e| fail(p, format!("{what}: {}: {e}", full.display())))?;
            let name = full.display().to_string();
            let made = if n == 2 {
                MixTable::parse_csv(&text, &name)
            } else {
                MixTable::parse_csv_path(&text, n, &name)
            };
            made.or_else(|m| fail(p, format!("{what}: {m}")))
        }
        _ => fail(
            p,
            format!(
                "{what}: the mix table is an array of {shape} rows or a .csv file of them; got {}",
                described(table)
            ),
        ),
    }
}
