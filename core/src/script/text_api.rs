//! `Text(text, height, depth, m, FontAspect.Regular, font,
//! HorizontalAlignment.Center, VerticalAlignment.Center)` with pyvcad's
//! argument order, defaults and enum names (`crate::text` lays it out).

use std::sync::Arc;

use rhai::{Dynamic, Engine, NativeCallContext as Ctx};

use super::RunContext;
use super::nodes_api::mk;
use super::values::*;
use crate::model::polygon2d::Polygon2d;
use crate::node::{Node, NodeKind};
use crate::text::{FontAspect, HorizontalAlignment, TextStyle, VerticalAlignment};

/// pyvcad's default font (absent on most Linux machines, where the
/// fallback applies, as in pyvcad).
const DEFAULT_FONT: &str = "Consolas";

pub(super) fn register(engine: &mut Engine, ctx: &RunContext) {
    register_enums(engine);
    let c = ctx.clone();
    let text = move |cc: &Ctx, args: &[Dynamic]| -> RResult<Node> { make(cc, &c, args) };
    // Every pyvcad arity, from (text, height, depth) up to all eight.
    macro_rules! arity {
        ($($arg:ident),+) => {{
            let t = text.clone();
            engine.register_fn("Text", move |c: Ctx, $($arg: Dynamic),+| t(&c, &[$($arg),+]));
        }};
    }
    arity!(a, b, d);
    arity!(a, b, d, m);
    arity!(a, b, d, m, f);
    arity!(a, b, d, m, f, n);
    arity!(a, b, d, m, f, n, h);
    arity!(a, b, d, m, f, n, h, v);
}

/// An enum argument, or pyvcad's default when absent.
fn enum_arg<T: Clone + 'static>(
    v: Option<&Dynamic>,
    default: T,
    what: &str,
    enum_name: &str,
    pos: rhai::Position,
) -> RResult<T> {
    match v {
        None => Ok(default),
        Some(v) => v.clone().try_cast::<T>().map_or_else(
            || {
                fail(
                    pos,
                    format!(
                        "Text: {what} must be a {enum_name} (for example {enum_name}::{}), got {}",
                        example(enum_name),
                        described(v)
                    ),
                )
            },
            Ok,
        ),
    }
}

fn example(enum_name: &str) -> &'static str {
    match enum_name {
        "FontAspect" => "Bold",
        "HorizontalAlignment" => "Left",
        _ => "Top",
    }
}

fn make(cc: &Ctx, ctx: &RunContext, args: &[Dynamic]) -> RResult<Node> {
    let p = cc.call_position();
    let Ok(text) = args[0].clone().into_string() else {
        return fail(
            p,
            format!(
                "Text: the first argument must be the text as a string, got {}",
                described(&args[0])
            ),
        );
    };
    let height = positive(&args[1], "Text: height", p)?;
    let depth = positive(&args[2], "Text: depth", p)?;
    let material = args.get(3).map_or(Ok(1), |m| material(m, p))?;
    let aspect = enum_arg(
        args.get(4),
        FontAspect::Regular,
        "aspect (5th argument)",
        "FontAspect",
        p,
    )?;
    let font = match args.get(5) {
        None => DEFAULT_FONT.to_owned(),
        Some(f) => f.clone().into_string().or_else(|_| {
            fail(
                p,
                format!(
                    "Text: font (6th argument) must be a family name such as \"DejaVu Sans\", got {}",
                    described(f)
                ),
            )
        })?,
    };
    let h_align = enum_arg(
        args.get(6),
        HorizontalAlignment::Center,
        "h_align (7th argument)",
        "HorizontalAlignment",
        p,
    )?;
    let v_align = enum_arg(
        args.get(7),
        VerticalAlignment::Center,
        "v_align (8th argument)",
        "VerticalAlignment",
        p,
    )?;
    let style = TextStyle {
        height,
        aspect,
        font,
        h_align,
        v_align,
    };
    let out = crate::text::outline(&text, &style).or_else(|e| fail(p, format!("Text: {e}")))?;
    let shape = Polygon2d::new(&out.contours)
        .ok_or(())
        .or_else(|_| fail(p, format!("Text: {text:?} has no outline with an area")))?;
    if !out.warnings.is_empty() {
        let at = match (p.line(), p.position()) {
            (Some(l), Some(c)) => format!("line {l}:{c}: "),
            _ => String::new(),
        };
        let mut st = ctx.lock();
        for w in out.warnings {
            st.warnings.push(format!("{at}Text: {w}"));
        }
    }
    Ok(mk(
        NodeKind::Text {
            text,
            shape: Arc::new(shape),
            depth,
            material,
        },
        p,
    ))
}

fn register_enums(engine: &mut Engine) {
    engine.register_type_with_name::<FontAspect>("FontAspect");
    engine.register_type_with_name::<HorizontalAlignment>("HorizontalAlignment");
    engine.register_type_with_name::<VerticalAlignment>("VerticalAlignment");
    let mut m = rhai::Module::new();
    for a in [
        FontAspect::Regular,
        FontAspect::Bold,
        FontAspect::Italic,
        FontAspect::BoldItalic,
    ] {
        m.set_var(a.name(), a);
    }
    engine.register_static_module("FontAspect", m.into());
    let mut m = rhai::Module::new();
    m.set_var("Left", HorizontalAlignment::Left);
    m.set_var("Center", HorizontalAlignment::Center);
    m.set_var("Right", HorizontalAlignment::Right);
    engine.register_static_module("HorizontalAlignment", m.into());
    let mut m = rhai::Module::new();
    m.set_var("Bottom", VerticalAlignment::Bottom);
    m.set_var("Center", VerticalAlignment::Center);
    m.set_var("Top", VerticalAlignment::Top);
    m.set_var("Top_First_Line", VerticalAlignment::Top_First_Line);
    engine.register_static_module("VerticalAlignment", m.into());
}
