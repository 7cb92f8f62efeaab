//! `volcad export` says when a gap between parts is narrower than two
//! voxels: in its summary and its manifest, and not at a voxel that keeps
//! the gap open.

mod cli_common;

use cli_common::{ok, tmp, volcad};

/// Two spheres of radius 1 mm, 0.2 mm apart.
const SPHERES: &str = r#"let m = default_materials();
Union(false, [Sphere(Vec3(0, 0, 0), 1, m.id("gray")), Sphere(Vec3(2.2, 0, 0), 1, m.id("gray"))])
"#;

const GAP: &str = "a gap between parts about 0.2 mm across (between a sphere and a sphere near (1.1, 0, 0) mm) is narrower than two cells of --voxel 0.5: it can close and join the parts on either side; --voxel 0.1 keeps it open";

#[test]
fn two_spheres_a_fifth_of_a_millimetre_apart_warn_at_half_a_millimetre_only() {
    let d = tmp("gaps");
    let design = d.path().join("spheres.rhai");
    std::fs::write(&design, SPHERES).unwrap();
    let export = |voxel: &str, out: &str| {
        let out = d.path().join(out);
        let o = volcad(&[
            "export",
            "mesh",
            design.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--voxel",
            voxel,
        ]);
        let stdout = ok(&o);
        let said = format!("{stdout}{}", String::from_utf8_lossy(&o.stderr));
        let manifest = std::fs::read_to_string(out.join("manifest.json")).unwrap();
        (said, manifest)
    };
    let (said, manifest) = export("0.5", "coarse");
    assert!(said.contains(GAP), "{said}");
    assert!(manifest.contains(GAP), "{manifest}");
    let (said, manifest) = export("0.05", "fine");
    assert!(!said.contains("a gap between parts"), "{said}");
    assert!(!manifest.contains("a gap between parts"), "{manifest}");
    assert!(
        said.contains("bodies: 2 (the design has 2 separate parts)"),
        "{said}"
    );
}
