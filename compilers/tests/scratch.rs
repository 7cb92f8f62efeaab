mod common;
use std::sync::atomic::AtomicBool;
use glam::DVec3;
use volcad_compilers::mesh::*;
#[test]
fn scratch() {
    let m = common::model(r#"let m = default_materials();
FGrade(["x/20+0.5", "-x/20+0.5"], [m.id("red"), m.id("blue")], true, RectPrism(Vec3(0,0,0), Vec3(20,10,5), m.id("gray")))"#);
    for (v, n) in [(0.25, 1), (0.25, 4), (0.5, 40)] {
        let p = MeshParams { voxel: DVec3::splat(v), segments: n, by: SegmentBy::Material(1), ..MeshParams::default() };
        let s = segment_meshes(&m, &p, &AtomicBool::new(false), |_, _| {}).unwrap();
        let tot: f64 = s.iter().map(|s| s.mesh.volume()).sum();
        println!("v {v} n {n}: total {tot} tris {}", s.iter().map(|s| s.mesh.triangles.len()).sum::<usize>());
        for x in s.iter().take(5) { println!("  {} {} tris {} vol {} f {} infill {}", x.name, x.voxels, x.mesh.triangles.len(), x.mesh.volume(), x.f, x.infill_percent); }
    }
    let sp = common::model(r#"let m = default_materials(); Sphere(Vec3(0,0,0), 10, m.id("red"))"#);
    let p = MeshParams { voxel: DVec3::splat(0.2), segments: 1, by: SegmentBy::Dominant, ..MeshParams::default() };
    let s = segment_meshes(&sp, &p, &AtomicBool::new(false), |_, _| {}).unwrap();
    let e = estimate_mesh(&sp, &p).unwrap();
    println!("sphere vol {} exact {} area {} tris {} est tris {}", s[0].mesh.volume(), 4.0/3.0*std::f64::consts::PI*1000.0, s[0].mesh.area(), s[0].mesh.triangles.len(), e.triangles);
}
