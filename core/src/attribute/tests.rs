//! Attribute rules on small designs with known answers.

use glam::DVec3;

use crate::Model;
use crate::aabb::Aabb;
use crate::model::Points;
use crate::script::{ScriptOptions, model_of};

fn try_model(src: &str) -> Result<Model, String> {
    let src = format!("let m = default_materials();\n{src}");
    model_of(&src, "t.rhai", &ScriptOptions::default()).map_err(|e| e.to_string())
}

fn model(src: &str) -> Model {
    try_model(src).unwrap_or_else(|e| panic!("{e}"))
}

/// Scalar attribute `name` at p.
fn at(m: &Model, name: &str, p: [f64; 3]) -> f64 {
    let i = m.attribute_index(name).expect("attribute");
    let mut o = [0.0];
    m.attribute_at(i, DVec3::from_array(p), &mut o).unwrap();
    o[0]
}

#[test]
fn constant_on_a_leaf_inside_only() {
    let m = model(
        "let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); s.set_attribute(\"modulus\", 2850.0); s",
    );
    assert_eq!(m.attributes().len(), 1);
    assert_eq!(m.attributes()[0].name, "modulus");
    assert_eq!(at(&m, "modulus", [1.0, 0.0, 0.0]), 2850.0);
    assert!(at(&m, "modulus", [6.0, 0.0, 0.0]).is_nan());
}

#[test]
fn no_attributes_no_evaluator() {
    let m = model("Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\"))");
    assert!(m.attributes().is_empty());
    assert!(m.attrs.is_none());
    assert!(
        m.require_attribute("modulus")
            .unwrap_err()
            .message
            .contains("none")
    );
}

#[test]
fn math_string_in_local_frame_and_other_attributes() {
    // The sphere is moved by 10 in x: x is the sphere's own frame.
    let m = model(
        "let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\"));
         s.set_attribute(\"temperature\", \"20 + x\");
         s.set_attribute(\"infill_density\", \"temperature * 2\");
         Translate(10.0, 0.0, 0.0, s)",
    );
    assert_eq!(at(&m, "temperature", [12.0, 0.0, 0.0]), 22.0);
    assert_eq!(at(&m, "infill_density", [12.0, 0.0, 0.0]), 44.0);
    // d is the node's signed distance.
    let m = model(
        "let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\")); s.set_attribute(\"depth\", \"-d\"); s",
    );
    assert!((at(&m, "depth", [1.0, 0.0, 0.0]) - 4.0).abs() < 1e-12);
}

#[test]
fn vectors_and_batch_equals_single() {
    let m = model(
        "let s = RectPrism(Vec3(0, 0, 0), Vec3(10, 10, 10), m.id(\"red\"));
         s.set_attribute(\"color\", [\"x/10 + 0.5\", 0.2, \"clamp(0, y/10 + 0.5, 1)\", 1.0]);
         s.set_attribute(\"dir\", Vec3(1, 2, 3));
         s",
    );
    let c = m.attribute_index("color").unwrap();
    let xs: Vec<f64> = (0..50).map(|i| -6.0 + 0.25 * i as f64).collect();
    let ys: Vec<f64> = xs.iter().map(|x| x * 0.5).collect();
    let zs = vec![0.0; xs.len()];
    let pts = Points {
        x: &xs,
        y: &ys,
        z: &zs,
    };
    let mut batch = vec![0.0; 4 * xs.len()];
    m.attribute_batch(c, pts, &mut batch).unwrap();
    for i in 0..xs.len() {
        let mut one = [0.0; 4];
        m.attribute_at(c, pts.get(i), &mut one).unwrap();
        for k in 0..4 {
            assert!(one[k] == batch[4 * i + k] || (one[k].is_nan() && batch[4 * i + k].is_nan()));
        }
    }
    let mut one = [0.0; 4];
    m.attribute_at(c, DVec3::new(2.0, 0.0, 0.0), &mut one)
        .unwrap();
    assert_eq!(one, [0.7, 0.2, 0.5, 1.0]);
    let d = m.attribute_index("dir").unwrap();
    let mut v = [0.0; 3];
    m.attribute_at(d, DVec3::ZERO, &mut v).unwrap();
    assert_eq!(v, [1.0, 2.0, 3.0]);
    // A buffer of the wrong length is an error, not a panic.
    assert!(m.attribute_at(d, DVec3::ZERO, &mut [0.0; 2]).is_err());
    assert!(m.attribute_at(9, DVec3::ZERO, &mut [0.0; 1]).is_err());
}
