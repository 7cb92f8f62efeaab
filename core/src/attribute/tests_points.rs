//! Scattered points as an attribute (`PointsField`), through scripts.

use glam::DVec3;

use crate::Model;
use crate::script::{ScriptOptions, model_of};

/// A script in a temporary folder beside `files`.
fn model_in_dir(src: &str, files: &[(&str, &str)]) -> Result<Model, String> {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let path = dir.path().join("t.rhai");
    let src = format!("let m = default_materials();\n{src}");
    model_of(&src, "t.rhai", &ScriptOptions::for_file(&path)).map_err(|e| e.to_string())
}

#[test]
fn a_points_csv_is_interpolated_by_inverse_distance() {
    let csv = "\u{feff}# two probes\nx,y,z,temperature,humidity\n-5,0,0,20,0.5\n5,0,0,60,0.5\n";
    let src = "let s = Sphere(Vec3(0, 0, 0), 8.0, m.id(\"red\"));
               s.set_attribute(\"temperature\", PointsField(\"temps.csv\", \"temperature\"));
               Translate(10.0, 0.0, 0.0, s)";
    let m = model_in_dir(src, &[("temps.csv", csv)]).unwrap();
    let i = m.attribute_index("temperature").unwrap();
    let at = |x: f64| {
        let mut o = [0.0];
        m.attribute_at(i, DVec3::new(x, 0.0, 0.0), &mut o).unwrap();
        o[0]
    };
    // In the sphere's frame: at a probe its value, half way the mean.
    assert_eq!(at(5.0), 20.0);
    assert_eq!(at(10.0), 40.0);
    // At local x = −3: weights 1/4 and 1/64.
    let want = (20.0 / 4.0 + 60.0 / 64.0) / (1.0 / 4.0 + 1.0 / 64.0);
    assert!((at(7.0) - want).abs() < 1e-12);
    assert!(at(30.0).is_nan());
    let b = crate::aabb::Aabb::new(DVec3::new(2.0, -8.0, -8.0), DVec3::new(18.0, 8.0, 8.0));
    let iv = m.attribute_interval(i, &b).unwrap();
    assert_eq!((iv.lo, iv.hi), (20.0, 60.0));
    let e = model_in_dir(
        "let s = Sphere(Vec3(0, 0, 0), 8.0, m.id(\"red\")); s.set_attribute(\"temperature\", PointsField(\"temps.csv\", \"pressure\")); s",
        &[("temps.csv", csv)],
    )
    .unwrap_err();
    assert!(
        e.contains("no column \"pressure\"; its value columns are temperature, humidity"),
        "{e}"
    );
    let e = model_in_dir(
        "let s = Sphere(Vec3(0, 0, 0), 8.0, m.id(\"red\")); s.set_attribute(\"temperature\", PointsField(\"temps.csv\", \"t\")); s",
        &[("temps.csv", "x,y,z,t\n1,2,3,4\n1,2,3,x4\n")],
    )
    .unwrap_err();
    assert!(e.contains("temps.csv:3: column 4 (\"t\") is \"x4\""), "{e}");
    assert!(e.contains("t.rhai:2:"), "{e}");
    let e = model_in_dir(
        "let s = Sphere(Vec3(0, 0, 0), 8.0, m.id(\"red\")); s.set_attribute(\"color\", PointsField(\"temps.csv\", \"t\")); s",
        &[("temps.csv", "x,y,z,t\n1,2,3,4\n")],
    )
    .unwrap_err();
    assert!(e.contains("Vec4"), "{e}");
}
