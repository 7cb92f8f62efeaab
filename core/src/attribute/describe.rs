//! Text of the attributes a design sets, node by node (`volcad info`, the
//! studio's probe), and of a value at a point (`volcad eval`).

use super::{AttrSource, AttributeInfo, AttributeKind, Component};
use crate::material::MaterialTable;
use crate::node::Node;

/// "modulus = 2850 on Sphere (made at line 3:9)" and "resolver modulus =
/// average on Union (...)" lines, parents before children, each node once;
/// materials are named from `table`.
pub fn describe_tree(root: &Node, table: &MaterialTable) -> Vec<String> {
    let mut out = Vec::new();
    let mut seen = std::collections::HashSet::new();
    let mut stack = vec![root];
    while let Some(n) = stack.pop() {
        if !seen.insert((n.ptr(), n.attrs_ptr())) {
            continue;
        }
        if let Some(a) = n.attributes() {
            for d in &a.defs {
                out.push(format!(
                    "{} ({}) = {} on {}",
                    d.name,
                    d.kind.name(),
                    source_text(&d.source),
                    n.describe()
                ));
            }
            if let Some(c) = &a.to_fractions {
                let (lo, hi) = c.table.value_range();
                let names: Vec<&str> = c.materials.iter().map(|m| table.name(*m)).collect();
                let (last, rest) = names.split_last().map_or(("", &[][..]), |(l, r)| (*l, r));
                out.push(format!(
                    "fractions = {} and {last} mixed for \"{}\" through a mix table over {lo}..{hi} on {}",
                    rest.join(", "),
                    c.from,
                    n.describe()
                ));
            }
            for (name, r, _) in &a.resolvers {
                out.push(format!(
                    "{name}: overlaps resolved by {} on {}",
                    r.describe(),
                    n.describe()
                ));
            }
        }
        stack.extend(n.kind().children().into_iter().rev());
    }
    out
}

fn source_text(s: &AttrSource) -> String {
    match s {
        AttrSource::Components(cs) => {
            let parts: Vec<String> = cs
                .iter()
                .map(|c| match c {
                    Component::Const(v) => v.to_string(),
                    Component::Text(t) => format!("\"{t}\""),
                })
                .collect();
            match parts.len() {
                1 => parts[0].clone(),
                3 => format!("Vec3({})", parts.join(", ")),
                _ => format!("Vec4({})", parts.join(", ")),
            }
        }
        AttrSource::Convert { from, map } => match map {
            super::ConvMap::Table(t) => {
                let (lo, hi) = t.input_range();
                format!("\"{from}\" through a table over {lo}..{hi}")
            }
            super::ConvMap::Expr(e) => format!("\"{e}\" of \"{from}\""),
            super::ConvMap::Mix { reuss, values } => format!(
                "{} mix of {} material values",
                if *reuss { "Reuss" } else { "Voigt" },
                values.len()
            ),
        },
        AttrSource::Data {
            field, column_name, ..
        } => format!(
            "column \"{column_name}\" of a SimulationField ({} nodes)",
            field.node_count()
        ),
        AttrSource::Image { map, channel } => {
            let (w, h) = map.picture().size();
            format!(
                "{} of picture \"{}\" ({w} x {h} px) projected along {}",
                match channel {
                    Some(c) => format!("{c:?}").to_lowercase(),
                    None => "RGBA".into(),
                },
                map.file(),
                map.axis().name()
            )
        }
        AttrSource::Points { cloud, column } => format!(
            "column \"{}\" of {} points, inverse-distance weighted",
            cloud.names()[*column],
            cloud.len()
        ),
    }
}

/// Component names of a kind for table headers: `name`, or `name.x`
/// `name.y` `name.z`, or `name.r` .. `name.a`.
pub fn column_names(info: &AttributeInfo) -> Vec<String> {
    let n = &info.name;
    match info.kind {
        AttributeKind::Scalar => vec![n.clone()],
        AttributeKind::Vec3 => ["x", "y", "z"].map(|c| format!("{n}.{c}")).to_vec(),
        AttributeKind::Vec4 => ["r", "g", "b", "a"].map(|c| format!("{n}.{c}")).to_vec(),
    }
}

/// A value as text: "2850", "1, 0, 0, 1", or "none" where it is NaN.
pub fn value_text(v: &[f64]) -> String {
    if v.iter().all(|x| x.is_nan()) {
        return "none".into();
    }
    v.iter().map(f64::to_string).collect::<Vec<_>>().join(", ")
}
