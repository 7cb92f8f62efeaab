//! `ImageField("photo.png", "z", [x0, y0, x1, y1])`: a picture projected
//! along an axis onto a rectangle of the node's local frame, as a colour
//! (`node.set_attribute("color", ImageField(...))`) or, with a channel
//! name, a scalar (see [`crate::attribute::ImageMap`]).

use std::sync::Arc;

use rhai::{Array, Engine, NativeCallContext as Ctx, Position};

use super::attribute_api::set_sourced;
use super::values::*;
use crate::attribute::{
    AttrSource, AttributeKind, CHANNELS, ImageAxis, ImageChannel, ImageMap, Picture,
};
use crate::node::Node;

/// `ImageField(file, axis, rect[, channel])` in scripts.
#[derive(Clone, Debug)]
pub struct ImageValue {
    /// The placed picture.
    pub map: Arc<ImageMap>,
    /// The channel of a scalar; `None`: RGBA.
    pub channel: Option<ImageChannel>,
}

/// The picture, axis and rectangle of one call, checked.
fn image_field(
    c: &super::RunContext,
    p: Position,
    file: &str,
    axis: &str,
    rect: &Array,
) -> RResult<Arc<ImageMap>> {
    let Some(ax) = ImageAxis::parse(axis) else {
        return fail(
            p,
            format!(
                "ImageField: axis \"{axis}\" is not one of \"x\", \"y\", \"z\"; give the axis the picture is projected along (\"z\": seen from above)"
            ),
        );
    };
    if rect.len() != 4 {
        return fail(
            p,
            format!(
                "ImageField: the rectangle has {} numbers; give four, [low, low, high, high] of the plane across the axis, e.g. [-20, -20, 20, 20]",
                rect.len()
            ),
        );
    }
    let mut r = [0.0; 4];
    for (o, v) in r.iter_mut().zip(rect) {
        *o = finite(v, "ImageField rectangle", p)?;
    }
    let full = c.resolve(file, p)?;
    let shown = full.display().to_string();
    let picture = super::file_cache::cached(&[full.as_path()], || Picture::load(&full, &shown))
        .or_else(|m| fail(p, format!("ImageField: {m}")))?;
    let map =
        ImageMap::new(picture, ax, r, file).or_else(|m| fail(p, format!("ImageField: {m}")))?;
    Ok(Arc::new(map))
}

pub(super) fn register(engine: &mut Engine, ctx: &super::RunContext) {
    engine.register_type_with_name::<ImageValue>("ImageField");
    let c = ctx.clone();
    engine.register_fn(
        "ImageField",
        move |cc: Ctx, file: &str, axis: &str, rect: Array| -> RResult<ImageValue> {
            let map = image_field(&c, cc.call_position(), file, axis, &rect)?;
            Ok(ImageValue { map, channel: None })
        },
    );
    let c = ctx.clone();
    engine.register_fn(
        "ImageField",
        move |cc: Ctx, file: &str, axis: &str, rect: Array, channel: &str| -> RResult<ImageValue> {
            let p = cc.call_position();
            let Some(ch) = ImageChannel::parse(channel) else {
                return fail(
                    p,
                    format!("ImageField: channel \"{channel}\" is not one of {CHANNELS}"),
                );
            };
            let map = image_field(&c, p, file, axis, &rect)?;
            Ok(ImageValue {
                map,
                channel: Some(ch),
            })
        },
    );
    engine.register_fn(
        "set_attribute",
        |cc: Ctx, n: &mut Node, name: &str, v: ImageValue| -> RResult<()> {
            let (kind, hint) = match v.channel {
                Some(_) => (
                    AttributeKind::Scalar,
                    "; drop the channel argument for a colour",
                ),
                None => (
                    AttributeKind::Vec4,
                    "; add a channel argument (\"luminance\", \"r\", ...) for a number",
                ),
            };
            let source = AttrSource::Image {
                map: v.map,
                channel: v.channel,
            };
            set_sourced(n, name, kind, source, cc.call_position(), hint)
        },
    );
}
