//! The order in which a node's attributes that read each other by name are
//! evaluated, and the refusal of cycles (`a = "b+1"`, `b = "a*2"`).

use super::prepared::{COORD_SLOTS, Own, OwnSrc, PComp, PConv};
use crate::model::PrepareError;
use crate::node::Node;

/// Variables read directly by `o` (bit i: slot i).
fn direct_used(o: &Own) -> u64 {
    match &o.src {
        OwnSrc::Comps(cs) => cs.iter().fold(0, |m, c| match c {
            PComp::Const(_) => m,
            PComp::Expr(e) => m | e.used_vars(),
        }),
        OwnSrc::Data { .. } | OwnSrc::Points { .. } | OwnSrc::Image { .. } => 0,
        // The math string's slot 9 is its input, not an own attribute.
        OwnSrc::Convert { from_own, map, .. } => {
            let coords = match map {
                PConv::Table(_) | PConv::Mix { .. } => 0,
                PConv::Expr(e) => e.used_vars() & ((1 << COORD_SLOTS) - 1),
            };
            coords | from_own.map_or(0, |j| 1u64 << (COORD_SLOTS + j))
        }
    }
}

/// Fill each attribute's `order` (the attributes it reads, transitively,
/// each after those it reads) and `used`; refuse a cycle.
pub(super) fn order_dependencies(n: &Node, own: &mut [Own]) -> Result<(), PrepareError> {
    let direct: Vec<u64> = own.iter().map(direct_used).collect();
    let count = own.len();
    let deps = |i: usize| -> Vec<usize> {
        (0..count)
            .filter(|j| direct[i] & (1u64 << (COORD_SLOTS + j)) != 0)
            .collect()
    };
    for start in 0..count {
        // Depth-first post-order from `start`; `path` holds the chain being
        // followed, so meeting one of it again is a cycle.
        let mut order = Vec::new();
        let mut done = vec![false; count];
        let mut path: Vec<(usize, Vec<usize>)> = vec![(start, deps(start))];
        while let Some((i, pending)) = path.last_mut() {
            let i = *i;
            let next = pending.pop();
            match next {
                Some(j) if path.iter().any(|(k, _)| *k == j) => {
                    let names: Vec<&str> = path
                        .iter()
                        .map(|(k, _)| own[*k].name.as_str())
                        .chain([own[j].name.as_str()])
                        .collect();
                    return Err(PrepareError {
                        node: n.describe(),
                        message: format!(
                            "attributes read each other in a cycle ({}); one of them must be a value that does not read the others",
                            names.join(" -> ")
                        ),
                    });
                }
                Some(j) if !done[j] => path.push((j, deps(j))),
                Some(_) => {}
                None => {
                    done[i] = true;
                    if i != start {
                        order.push(i);
                    }
                    path.pop();
                }
            }
        }
        let used = order.iter().chain([&start]).fold(0, |m, &k| m | direct[k]);
        own[start].order = order;
        own[start].used = used;
    }
    Ok(())
}
