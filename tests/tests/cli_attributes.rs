//! Attributes in the CLI: `volcad info` lists them per node, `volcad eval`
//! prints each at the point, `volcad sample --attributes` adds columns.

mod cli_common;

use cli_common::{fails, ok, tmp, volcad};

/// A bar 20 mm long in x whose modulus rises along x, with a colour, and a
/// ball on top whose modulus the union averages where they overlap.
const DESIGN: &str = r#"let m = default_materials();
let bar = RectPrism(Vec3(0, 0, 0), Vec3(20, 4, 4), m.id("red"));
bar.set_attribute("modulus", "1000 + 50*x");
bar.set_attribute("color", Vec4(1, 0, 0, 1));
let ball = Sphere(Vec3(10, 0, 0), 3.0, m.id("blue"));
ball.set_attribute("modulus", 500.0);
let u = Union(false, [bar, ball]);
u.set_attribute_conflict_resolver("modulus", "average");
u
"#;

#[test]
fn info_eval_and_sample_show_attributes() {
    let scratch = tmp("attrs");
    let d = scratch.path();
    let design = d.join("bar.rhai");
    std::fs::write(&design, DESIGN).unwrap();
    let design = design.to_str().unwrap();

    let out = ok(&volcad(&["info", design]));
    assert!(
        out.contains(
            "attribute:   modulus (number) = \"1000 + 50*x\" on RectPrism (made at line 2:"
        ),
        "{out}"
    );
    assert!(out.contains("color (Vec4) = Vec4(1, 0, 0, 1)"), "{out}");
    assert!(
        out.contains("modulus: overlaps resolved by average on Union"),
        "{out}"
    );

    let out = ok(&volcad(&["eval", design, "--", "-4", "0", "0"]));
    assert!(out.contains("attribute modulus: 800"), "{out}");
    assert!(out.contains("attribute color: 1, 0, 0, 1"), "{out}");
    // In the overlap: (1000 + 50·9 + 500)/2.
    let out = ok(&volcad(&["eval", design, "9", "0", "0"]));
    assert!(out.contains("attribute modulus: 975"), "{out}");
    // Outside: no attribute lines.
    let out = ok(&volcad(&["eval", design, "50", "0", "0"]));
    assert!(!out.contains("attribute"), "{out}");

    let pts = d.join("in.csv");
    std::fs::write(&pts, "x,y,z\n-4,0,0\n50,0,0\n").unwrap();
    let csv = d.join("out.csv");
    let run = |attrs: &str| {
        volcad(&[
            "sample",
            design,
            "--points",
            pts.to_str().unwrap(),
            "--out",
            csv.to_str().unwrap(),
            "--attributes",
            attrs,
        ])
    };
    ok(&run("modulus,color"));
    let text = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[0],
        "x,y,z,distance,red,blue,modulus,color.r,color.g,color.b,color.a"
    );
    assert!(lines[1].ends_with(",800,1,0,0,1"), "{}", lines[1]);
    assert!(lines[2].ends_with(",NaN,NaN,NaN,NaN,NaN"), "{}", lines[2]);

    // An attribute the design does not have: the ones it has, no output.
    std::fs::remove_file(&csv).unwrap();
    let err = fails(&run("shore_hardness"));
    assert!(
        err.contains("no attribute \"shore_hardness\"") && err.contains("color, modulus"),
        "{err}"
    );
    assert!(!csv.exists());
}

#[test]
fn a_value_out_of_range_names_node_point_and_value() {
    let scratch = tmp("attrs-range");
    let d = scratch.path();
    let design = d.join("neg.rhai");
    std::fs::write(
        &design,
        "let m = default_materials(); let s = Sphere(Vec3(0, 0, 0), 5.0, m.id(\"red\"));\ns.set_attribute(\"modulus\", \"100*x\"); s\n",
    )
    .unwrap();
    let err = fails(&volcad(&[
        "eval",
        design.to_str().unwrap(),
        "--",
        "-2",
        "0",
        "0",
    ]));
    assert!(
        err.contains("Sphere (made at line 1:")
            && err.contains("set_attribute at line 2:")
            && err.contains("gives -200 at (-2, 0, 0)"),
        "{err}"
    );
}

#[test]
fn info_names_the_materials_a_mix_table_converts_to() {
    let out = ok(&volcad(&["info", &cli_common::example("shore_grip.rhai")]));
    assert!(
        out.contains(
            "attribute:   fractions = Agilus30Clr and VeroClear mixed for \"shore_hardness\" through a mix table over 30..95"
        ),
        "{out}"
    );
}
