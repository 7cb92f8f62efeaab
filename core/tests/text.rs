//! The Text node: glyph distances against a brute-force polygon distance,
//! interval bounds, pyvcad 2.3.4's layout, kerning, and bad inputs. Every
//! test names "DejaVu Sans", which resolves to the built-in font, so the
//! outlines are the same on every machine.

// A test crate: its helper functions stop on a failed setup as its tests do.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use glam::{DVec2, DVec3};
use volcad_core::bench::XorShift;
use volcad_core::model::polygon2d::Polygon2d;
use volcad_core::script::{ScriptOptions, run_script};
use volcad_core::text::{
    FontAspect, HorizontalAlignment, TextOutline, TextStyle, VerticalAlignment, outline,
};
use volcad_core::{Aabb, Model};

fn style(h: HorizontalAlignment, v: VerticalAlignment) -> TextStyle {
    TextStyle {
        height: 10.0,
        aspect: FontAspect::Regular,
        font: "DejaVu Sans".into(),
        h_align: h,
        v_align: v,
    }
}

fn centred(text: &str) -> TextOutline {
    outline(
        text,
        &style(HorizontalAlignment::Center, VerticalAlignment::Center),
    )
    .unwrap()
}

fn bounds(o: &TextOutline) -> (DVec2, DVec2) {
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = -lo;
    for p in o.contours.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    (lo, hi)
}

/// Every edge, and even-odd containment from all crossings of a ray.
fn brute(contours: &[Vec<DVec2>], p: DVec2) -> f64 {
    let mut d2 = f64::INFINITY;
    let mut inside = false;
    for c in contours {
        for i in 0..c.len() {
            let (a, b) = (c[i], c[(i + 1) % c.len()]);
            let e = b - a;
            let t = ((p - a).dot(e) / e.length_squared()).clamp(0.0, 1.0);
            d2 = d2.min((p - a - e * t).length_squared());
            if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * e.x / e.y {
                inside = !inside;
            }
        }
    }
    if inside { -d2.sqrt() } else { d2.sqrt() }
}

fn model(src: &str) -> (Model, Vec<String>) {
    let d =
        run_script(src, "text.rhai", &ScriptOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let m = Model::prepare(&d.root, d.materials.clone()).unwrap_or_else(|e| panic!("{e}"));
    (m, d.warnings)
}

fn script_error(src: &str) -> String {
    match run_script(src, "text.rhai", &ScriptOptions::default()) {
        Ok(_) => panic!("{src} ran"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn glyph_distances_match_brute_force() {
    let o = centred("Hello, World!\nAg8 %&@ ÅÉ");
    let poly = Polygon2d::new(&o.contours).unwrap();
    let (lo, hi) = bounds(&o);
    let mut rng = XorShift::new(11);
    for _ in 0..3000 {
        let p = lo - 2.0 + (hi - lo + 4.0) * DVec2::new(rng.next_f64(), rng.next_f64());
        let (got, want) = (poly.signed_distance(p), brute(&o.contours, p));
        assert!((got - want).abs() < 1e-12, "{p}: {got} vs {want}");
    }
}

#[test]
fn the_node_is_the_extruded_polygon() {
    let (m, warnings) =
        model(r#"Text("Volcad\nlabel", 8.0, 1.5, 1, FontAspect::Regular, "DejaVu Sans")"#);
    assert!(warnings.is_empty(), "{warnings:?}");
    let o = centred_at("Volcad\nlabel", 8.0);
    let b = m.bbox();
    assert_eq!((b.min.z, b.max.z), (-0.75, 0.75));
    let mut rng = XorShift::new(5);
    for _ in 0..2000 {
        let p = b.min - 1.0
            + (b.size() + 2.0) * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
        let d2 = brute(&o.contours, DVec2::new(p.x, p.y));
        let dz = p.z.abs() - 0.75;
        let want = d2.max(dz).min(0.0) + DVec2::new(d2, dz).max(DVec2::ZERO).length();
        assert!((m.distance(p) - want).abs() < 1e-12, "{p}");
    }
}

fn centred_at(text: &str, height: f64) -> TextOutline {
    let mut s = style(HorizontalAlignment::Center, VerticalAlignment::Center);
    s.height = height;
    outline(text, &s).unwrap()
}

#[test]
fn interval_bounds_contain_samples() {
    let (m, _) = model(r#"Text("Bound 42", 10.0, 2.0, 1, FontAspect::Regular, "DejaVu Sans")"#);
    let bb = m.bbox();
    let mut rng = XorShift::new(9);
    for _ in 0..300 {
        let c = bb.min + bb.size() * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
        let s = DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * 3.0;
        let b = Aabb::new(c, c + s);
        let i = m.interval(&b);
        for _ in 0..20 {
            let p = b.min + b.size() * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
            let d = m.distance(p);
            assert!(
                i.lo <= d && d <= i.hi,
                "{d} outside [{}, {}] over {b:?}",
                i.lo,
                i.hi
            );
        }
    }
}

/// pyvcad 2.3.4 (`Text(t, 10, 2, 1, ..., font="DejaVu Sans")`, then
/// `bounding_box()`), turned by 180° about z: pyvcad's text reads upside
/// down seen from +z, ours reads along +x (docs/PYVCAD.md).
#[test]
fn layout_matches_pyvcad() {
    use HorizontalAlignment as H;
    use VerticalAlignment as V;
    let cases: &[(&str, H, V, [f64; 4])] = &[
        ("H", H::Center, V::Center, [-2.778, -3.462, 2.778, 3.828]),
        ("H", H::Left, V::Center, [0.981, -3.462, 6.538, 3.828]),
        ("H", H::Right, V::Center, [-6.538, -3.462, -0.981, 3.828]),
        ("H\nH", H::Center, V::Center, [-2.778, -9.282, 2.778, 9.648]),
        ("H\nH", H::Center, V::Bottom, [-2.778, 0.0, 2.778, 18.931]),
        ("H\nH", H::Center, V::Top, [-2.778, -20.923, 2.778, -1.992]),
        (
            "H\nH",
            H::Center,
            V::Top_First_Line,
            [-2.778, -11.641, 2.778, 7.29],
        ),
        (
            "HH\nH",
            H::Center,
            V::Center,
            [-6.538, -9.282, 6.538, 9.648],
        ),
        (
            "Hello",
            H::Center,
            V::Center,
            [-11.692, -3.604, 12.126, 4.136],
        ),
        (
            "AV",
            H::Left,
            V::Top_First_Line,
            [0.0781, 0.0, 12.959, 7.29],
        ),
        (
            "To",
            H::Left,
            V::Top_First_Line,
            [-0.0293, -0.1416, 9.9805, 7.29],
        ),
        (
            "Hello",
            H::Left,
            V::Top_First_Line,
            [0.9814, -0.1416, 24.7998, 7.5977],
        ),
    ];
    for (text, h, v, want) in cases {
        let o = outline(text, &style(*h, *v)).unwrap();
        let (lo, hi) = bounds(&o);
        let got = [lo.x, lo.y, hi.x, hi.y];
        for k in 0..4 {
            // pyvcad's figures are rounded to 1e-3 or 1e-4; curves are
            // flattened to within 5 µm.
            assert!(
                (got[k] - want[k]).abs() < 2e-3,
                "{text:?} {h:?} {v:?}: {got:?} vs {want:?}"
            );
        }
    }
}

#[test]
fn kerning_pair_is_narrower_than_unkerned() {
    let s = style(HorizontalAlignment::Left, VerticalAlignment::Top_First_Line);
    let w = |t: &str| outline(t, &s).unwrap().line_widths[0];
    let (a, v, av) = (w("A"), w("V"), w("AV"));
    assert!(av < a + v - 0.5, "AV {av} vs A + V {}", a + v);
    // pyvcad 2.3.4 puts V's origin at 6.2012 mm after A's (A's advance is
    // 6.8408 mm): a pair adjustment of −0.6396 mm at 10 mm.
    assert!((av - a - v + 0.6396).abs() < 1e-3, "{}", av - a - v);
    // A pair the font does not kern keeps the plain advances.
    assert!((w("HH") - 2.0 * w("H")).abs() < 1e-12);
}

#[test]
fn lines_are_aligned_one_by_one() {
    let o = outline(
        "Wide line\nab",
        &style(HorizontalAlignment::Right, VerticalAlignment::Top),
    )
    .unwrap();
    assert_eq!(o.line_widths.len(), 2);
    assert!(o.line_widths[0] > 2.0 * o.line_widths[1]);
    // Right-aligned: both lines end at x = 0 (their last glyph's advance).
    let (_, hi) = bounds(&o);
    assert!(hi.x <= 0.0 && hi.x > -1.0, "{hi}");
    assert!(o.baselines[0] > o.baselines[1]);
    // DejaVu Sans: ascender 1901, descender −483, no gap (of 2048 units).
    let spacing = 10.0 * (1901.0 + 483.0) / 2048.0;
    assert!((o.baselines[0] - o.baselines[1] - spacing).abs() < 1e-12);
}

/// Points inside pyvcad 2.3.4's `Text("Ag\nB", 10, 2, 1, font="DejaVu
/// Sans")` at z = 0 (probed at (−x, −y), its text being turned by 180°).
#[test]
fn inside_agrees_with_pyvcad() {
    let (m, _) = model(r#"Text("Ag\nB", 10.0, 2.0, 1, FontAspect::Regular, "DejaVu Sans")"#);
    let probes = [
        (-2.62, 0.885, false),
        (-1.3, 2.078, false),
        (1.257, -8.689, true),
        (-4.868, 6.749, false),
        (-2.406, -5.313, true),
        (4.956, -0.595, false),
        (3.365, -0.473, false),
        (1.391, -6.988, false),
        (1.349, 7.361, false),
        (0.232, 4.825, false),
        (1.714, -8.719, true),
        (2.582, 1.822, false),
        (-1.987, -9.38, false),
        (3.655, -0.545, false),
        (2.188, 7.576, true),
        (2.141, 8.422, false),
        (-1.05, 6.018, false),
        (-0.554, 8.712, false),
        (3.789, -8.051, false),
        (-3.64, -5.66, false),
        (4.655, -1.277, false),
        (1.266, -3.979, false),
        (0.072, -2.283, true),
        (-1.491, 1.701, false),
    ];
    // docs/PYVCAD.md's way to pyvcad's orientation: probe as pyvcad was.
    let (turned, _) = model(
        r#"Rotate(0, 0, 180, Vec3(0, 0, 0),
                  Text("Ag\nB", 10.0, 2.0, 1, FontAspect::Regular, "DejaVu Sans"))"#,
    );
    for (x, y, inside) in probes {
        let d = m.distance(DVec3::new(x, y, 0.0));
        assert_eq!(d <= 0.0, inside, "({x}, {y}): {d}");
        let d = turned.distance(DVec3::new(-x, -y, 0.0));
        assert_eq!(d <= 0.0, inside, "turned ({x}, {y}): {d}");
    }
}

#[test]
fn defaults_and_enums_follow_pyvcad() {
    // pyvcad's defaults: material 1, Regular, "Consolas", centred both ways.
    let (m, warnings) = model(r#"Text("H", 10.0, 2.0)"#);
    let b = m.bbox();
    assert!(
        (b.min.x + 2.778).abs() < 2e-3 && (b.max.y - 3.828).abs() < 2e-3,
        "{b:?}"
    );
    if warnings.iter().any(|w| w.contains("Consolas")) {
        assert!(warnings[0].contains("line 1:1"), "{warnings:?}");
    }
    let (m, _) = model(
        r#"Text("H", 10.0, 2.0, 1, FontAspect::Regular, "DejaVu Sans",
                HorizontalAlignment::Left, VerticalAlignment::Top_First_Line)"#,
    );
    assert!((m.bbox().min.x - 0.981).abs() < 2e-3 && m.bbox().min.y.abs() < 1e-9);
}

#[test]
fn bad_inputs_say_what_to_write() {
    let e = script_error(r#"Text("", 10.0, 2.0)"#);
    assert!(e.contains("1:1") && e.contains("empty"), "{e}");
    let e = script_error(r#"Text("A", -10.0, 2.0)"#);
    assert!(e.contains("Text: height must be > 0"), "{e}");
    let e = script_error(r#"Text("A", 10.0, 0)"#);
    assert!(e.contains("Text: depth must be > 0"), "{e}");
    let e = script_error(r#"Text("   ", 10.0, 2.0, 1, FontAspect::Regular, "DejaVu Sans")"#);
    assert!(e.contains("no visible glyph"), "{e}");
    let e = script_error(r#"Text(42, 10.0, 2.0)"#);
    assert!(
        e.contains("must be the text as a string, got an integer"),
        "{e}"
    );
    let e = script_error(r#"Text("A", 10.0, 2.0, 1, "Bold")"#);
    assert!(
        e.contains("aspect (5th argument) must be a FontAspect"),
        "{e}"
    );
    let e = script_error(
        r#"Text("A", 10.0, 2.0, 1, FontAspect::Bold, "DejaVu Sans", VerticalAlignment::Top)"#,
    );
    assert!(
        e.contains("h_align (7th argument) must be a HorizontalAlignment"),
        "{e}"
    );
    let long = "x".repeat(volcad_core::text::MAX_CHARS + 1);
    let e = script_error(&format!("Text(\"{long}\", 1.0, 1.0)"));
    assert!(e.contains("at most 10000"), "{e}");
}

#[test]
fn unknown_family_falls_back_with_a_warning() {
    let (m, warnings) = model(
        r#"
        let t = Text("Hi", 10.0, 2.0, 1, FontAspect::Regular, "No Such Family 7");
        t"#,
    );
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    let w = &warnings[0];
    assert!(
        w.contains("line 2:17") && w.contains("\"No Such Family 7\"") && w.contains("DejaVu Sans"),
        "{w}"
    );
    // The fallback is the same outline as asking for DejaVu Sans.
    let (d, _) = model(r#"Text("Hi", 10.0, 2.0, 1, FontAspect::Regular, "DejaVu Sans")"#);
    assert_eq!(format!("{:?}", m.bbox()), format!("{:?}", d.bbox()));
}

#[test]
fn missing_glyphs_warn_and_leave_a_gap() {
    let (m, warnings) = model(r#"Text("A中B", 10.0, 2.0, 1, FontAspect::Regular, "DejaVu Sans")"#);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].contains("U+4E2D") && warnings[0].contains("DejaVu Sans"),
        "{warnings:?}"
    );
    let (ab, _) = model(r#"Text("AB", 10.0, 2.0, 1, FontAspect::Regular, "DejaVu Sans")"#);
    assert!(m.bbox().size().x > ab.bbox().size().x + 2.0);
}
