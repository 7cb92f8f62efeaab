//! `PointsField("temps.csv", "temperature")`: a value column of scattered
//! points as an attribute value, `node.set_attribute("temperature",
//! PointsField(...))` (see [`crate::attribute::PointCloud`]).

use std::sync::Arc;

use rhai::{Engine, NativeCallContext as Ctx};

use super::attribute_api::set_sourced;
use super::values::*;
use crate::attribute::{AttrSource, AttributeKind, PointCloud};
use crate::node::Node;

/// `PointsField(file, column)` in scripts: one value column of a points
/// CSV.
#[derive(Clone, Debug)]
pub struct PointsValue {
    /// The points.
    pub cloud: Arc<PointCloud>,
    /// The column's index in [`PointCloud::names`].
    pub column: usize,
}

pub(super) fn register(engine: &mut Engine, ctx: &super::RunContext) {
    engine.register_type_with_name::<PointsValue>("PointsField");
    let c = ctx.clone();
    engine.register_fn(
        "PointsField",
        move |cc: Ctx, file: &str, column: &str| -> RResult<PointsValue> {
            let p = cc.call_position();
            let full = c.resolve(file, p)?;
            let shown = full.display().to_string();
            let text =
                std::fs::read(&full).or_else(|e| fail(p, format!("PointsField: {shown}: {e}")))?;
            let text = String::from_utf8(text).or_else(|_| {
                fail(
                    p,
                    format!("PointsField: {shown} is not UTF-8 text; save it as a plain CSV"),
                )
            })?;
            let cloud = PointCloud::parse(&text, &shown)
                .or_else(|m| fail(p, format!("PointsField: {m}")))?;
            let Some(col) = cloud.names().iter().position(|n| n == column) else {
                return fail(
                    p,
                    format!(
                        "PointsField: {shown} has no column \"{column}\"; its value columns are {}",
                        cloud.names().join(", ")
                    ),
                );
            };
            Ok(PointsValue {
                cloud: Arc::new(cloud),
                column: col,
            })
        },
    );
    engine.register_fn(
        "set_attribute",
        |cc: Ctx, n: &mut Node, name: &str, v: PointsValue| -> RResult<()> {
            let source = AttrSource::Points {
                cloud: v.cloud,
                column: v.column,
            };
            let p = cc.call_position();
            set_sourced(n, name, AttributeKind::Scalar, source, p, "")
        },
    );
}
