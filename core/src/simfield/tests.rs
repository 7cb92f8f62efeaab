//! Tests of [`crate::simfield`] on the seat dataset and small hand-made
//! inputs.

use std::path::{Path, PathBuf};

use glam::DVec3;

use super::{SimField, SimFieldError};
use crate::trimesh::tests::{Rng, temp_path, throughput};

const SEAT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/seat/");
/// The mesh and the table CSV ship with the bicycle-seat example.
const EXAMPLE_DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/examples/data/");

fn seat(name: &str) -> PathBuf {
    if name == "seat.inp" || name == "seat_displacement_table.csv" {
        Path::new(EXAMPLE_DATA).join(name)
    } else {
        Path::new(SEAT).join(name)
    }
}

/// The CSV rows as (x, y, z, dx, dy, dz), in node order.
fn csv_rows() -> Vec<[f64; 6]> {
    std::fs::read_to_string(seat("seat_displacement.csv"))
        .unwrap()
        .lines()
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|c| c.trim().parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3], v[4], v[5]]
        })
        .collect()
}

fn check_seat(f: &SimField) {
    assert_eq!(f.node_count(), 10679);
    assert_eq!(f.tet_count(), 50105);
    assert_eq!(f.variable_names(), ["dx", "dy", "dz", "len"]);
    assert!(f.boundary_mesh().is_closed_manifold(), "{:?}", f.warnings());
    assert_eq!(f.boundary_mesh().triangle_count(), 10176);
    assert!((f.boundary_mesh().volume() - 658_174.0).abs() < 1000.0);
    let rows = csv_rows();
    let mut out = [0.0; 4];
    let mut max_len: f64 = 0.0;
    for (n, r) in rows.iter().enumerate() {
        let p = f.nodes()[n];
        assert!(f.sample(p, &mut out), "node {n} at {p} not located");
        for k in 0..3 {
            assert!(
                (out[k] - r[3 + k]).abs() < 1e-6,
                "node {n}: {out:?} vs {r:?}"
            );
        }
        max_len = max_len.max(out[3]);
    }
    assert!((max_len - 7.354).abs() < 1e-3, "{max_len}");
    let (_, hi) = f.variable_range(3).unwrap();
    assert!((hi - 7.354).abs() < 1e-3);
}

#[test]
fn seat_bounds_hold_at_every_sample_of_random_boxes() {
    let f = SimField::load(&seat("seat.inp"), &seat("seat_displacement_table.csv")).unwrap();
    let bb = f.bbox();
    let mut rng = Rng::new(11);
    let mut bounded = 0;
    let mut iv = [crate::interval::Interval::point(0.0); 4];
    let mut out = [0.0; 4];
    for i in 0..300 {
        let size = [0.5, 2.0, 6.0][i % 3];
        let c = rng.in_box(&bb);
        let b = crate::aabb::Aabb::new(c - DVec3::splat(size), c + DVec3::splat(size));
        if !f.bounds(&b, &mut iv) {
            continue;
        }
        bounded += 1;
        for _ in 0..40 {
            let p = rng.in_box(&b);
            if !f.sample(p, &mut out) {
                continue;
            }
            for (v, (x, i)) in out.iter().zip(&iv).enumerate() {
                assert!(
                    i.lo - 1e-9 <= *x && *x <= i.hi + 1e-9,
                    "variable {v} = {x} outside {i:?} at {p}"
                );
            }
        }
    }
    assert!(bounded > 150, "{bounded} boxes bounded");
}

#[test]
fn seat_bounds_from_the_node_table_equal_the_tetrahedra_one_by_one() {
    let f = SimField::load(&seat("seat.inp"), &seat("seat_displacement_table.csv")).unwrap();
    let bb = f.bbox();
    let mut rng = Rng::new(23);
    // The same field without its table: bounds from each tetrahedron's
    // nodal rows (what a field too large for a table uses).
    let mut one_by_one = f.clone();
    one_by_one.ranges = None;
    assert!(f.ranges.is_some());
    let mut iv = [crate::interval::Interval::point(0.0); 4];
    let mut want_iv = iv;
    let (mut bounded, mut too_many) = (0, 0);
    for i in 0..3000 {
        // From a fraction of one tetrahedron to more than MAX_BOUND_TETS.
        let size = [0.2, 1.0, 3.0, 6.0, 10.0, 20.0][i % 6];
        let c = rng.in_box(&bb);
        let b = crate::aabb::Aabb::new(c - DVec3::splat(size), c + DVec3::splat(size));
        let got = f.bounds(&b, &mut iv);
        let want = one_by_one.bounds(&b, &mut want_iv);
        assert_eq!(got, want, "box {b:?}");
        if !want {
            too_many += usize::from(f.locator.overlapping(&b, |_| false));
            continue;
        }
        bounded += 1;
        // dx, dy, dz and len, bit for bit.
        for (k, (g, w)) in iv.iter().zip(&want_iv).enumerate() {
            assert_eq!(g.lo.to_bits(), w.lo.to_bits(), "box {b:?} variable {k}");
            assert_eq!(g.hi.to_bits(), w.hi.to_bits(), "box {b:?} variable {k}");
        }
    }
    assert!(bounded > 1000, "{bounded} boxes bounded");
    assert!(too_many < 3000 && bounded < 3000, "{too_many}");
}

#[test]
fn seat_headerless_and_table_agree() {
    let a = SimField::load(&seat("seat.inp"), &seat("seat_displacement.csv")).unwrap();
    check_seat(&a);
    assert!(a.warnings().is_empty(), "{:?}", a.warnings());
    let b = SimField::load(&seat("seat.inp"), &seat("seat_displacement_table.csv")).unwrap();
    check_seat(&b);
    // The full CalculiX deck: sets, material, step … are skipped.
    let c = SimField::load(&seat("seat_ccx.inp"), &seat("seat_displacement_table.csv")).unwrap();
    assert_eq!((c.node_count(), c.tet_count()), (10679, 50105));
    let mut rng = Rng::new(5);
    let (mut oa, mut oc) = ([0.0; 4], [0.0; 4]);
    for _ in 0..200 {
        let p = rng.in_box(&a.bbox());
        assert_eq!(a.sample(p, &mut oa), c.sample(p, &mut oc));
        assert_eq!(oa, oc);
    }
}

#[test]
fn seat_linear_field_is_exact_and_inside_agrees_with_distance() {
    let base = SimField::load(&seat("seat.inp"), &seat("seat_displacement.csv")).unwrap();
    let f_of = |p: DVec3| 2.0 * p.x - p.y + 3.0 * p.z + 1.0;
    let values: Vec<f64> = base.nodes().iter().map(|&p| f_of(p)).collect();
    let f = SimField::from_parts(
        base.nodes().to_vec(),
        base.tets().to_vec(),
        vec![("f".into(), values)],
    )
    .unwrap();
    assert_eq!(f.variable_names(), ["f"]);
    let mut rng = Rng::new(11);
    let mut inside = 0;
    let mut out = [0.0];
    for _ in 0..5000 {
        let p = rng.in_box(&f.bbox());
        let d = f.signed_distance(p);
        let found = f.sample(p, &mut out);
        if d.abs() > 1e-6 {
            assert_eq!(found, d < 0.0, "{p}: d = {d}");
        }
        if found {
            inside += 1;
            assert!(
                (out[0] - f_of(p)).abs() < 1e-9,
                "{p}: {} vs {}",
                out[0],
                f_of(p)
            );
            let (t, w) = f.locate(p).unwrap();
            let q: DVec3 = (0..4)
                .map(|k| f.nodes()[f.tets()[t as usize][k] as usize] * w[k])
                .sum();
            assert!((q - p).length() < 1e-9);
        }
    }
    assert!(inside > 1000, "{inside}");
    assert!(!f.sample(DVec3::new(-50.0, 0.0, 0.0), &mut out));
    assert!(!f.sample(DVec3::NAN, &mut out));
}

#[test]
fn every_cell_near_tetrahedra_starts_a_walk() {
    // Cells the boundary crosses with their centre outside used to keep no
    // start, and their points inside the mesh searched the BVH.
    let f = SimField::load(&seat("seat.inp"), &seat("seat_displacement.csv")).unwrap();
    assert_eq!(f.locator.unstarted_cells(), 0);
}

#[test]
fn points_on_shared_faces_and_nodes_locate_the_same_whatever_came_before() {
    // Each thread starts from the tetrahedron it found last; a point on a
    // face two tetrahedra share (or on a node) is inside both, and used to
    // be located in whichever the previous point left it in.
    let f = SimField::load(&seat("seat.inp"), &seat("seat_displacement.csv")).unwrap();
    let (nodes, tets) = (f.nodes(), f.tets());
    let centroid = |t: usize| tets[t].iter().map(|&n| nodes[n as usize]).sum::<DVec3>() / 4.0;
    // Interior faces: sorted node triples that two tetrahedra list.
    let mut faces: Vec<([u32; 3], usize)> = Vec::new();
    for (t, tet) in tets.iter().enumerate() {
        for skip in 0..4 {
            let mut key: Vec<u32> = (0..4).filter(|&i| i != skip).map(|i| tet[i]).collect();
            key.sort_unstable();
            faces.push(([key[0], key[1], key[2]], t));
        }
    }
    faces.sort_unstable();
    let shared: Vec<(DVec3, [usize; 2])> = faces
        .windows(2)
        .filter(|w| w[0].0 == w[1].0)
        .step_by(97)
        .map(|w| {
            let p = w[0].0.iter().map(|&n| nodes[n as usize]).sum::<DVec3>() / 3.0;
            (p, [w[0].1, w[1].1])
        })
        .collect();
    assert!(shared.len() > 500, "{}", shared.len());
    // A node and two tetrahedra around it.
    let around = |n: u32| -> Vec<usize> {
        (0..tets.len())
            .filter(|&t| tets[t].contains(&n))
            .take(2)
            .collect()
    };
    let at_nodes: Vec<(DVec3, [usize; 2])> = (0..nodes.len() as u32)
        .step_by(211)
        .filter_map(|n| match around(n)[..] {
            [a, b] => Some((nodes[n as usize], [a, b])),
            _ => None,
        })
        .collect();
    let bits = |p: DVec3| {
        let (t, w) = f.locate(p).expect("on the mesh");
        let mut out = [0.0; 4];
        assert!(f.sample(p, &mut out));
        (t, w.map(f64::to_bits), out.map(f64::to_bits))
    };
    for (p, [a, b]) in shared.iter().chain(&at_nodes) {
        f.locate(centroid(*a));
        let after_a = bits(*p);
        f.locate(centroid(*b));
        let after_b = bits(*p);
        assert_eq!(after_a, after_b, "{p} after tetrahedra {a} and {b}");
    }
}

/// Two tetrahedra sharing the face (1, 2, 3); the second one is inverted.
fn two_tets() -> (Vec<DVec3>, Vec<[u32; 4]>) {
    let nodes = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE];
    (nodes, vec![[0, 1, 2, 3], [4, 1, 2, 3]])
}

#[test]
fn two_tets_from_parts() {
    let (nodes, tets) = two_tets();
    let cols = vec![
        ("dx".to_string(), vec![0.0, 3.0, 0.0, 0.0, 1.0]),
        ("dy".to_string(), vec![0.0, 0.0, 4.0, 0.0, 1.0]),
        ("dz".to_string(), vec![0.0, 0.0, 0.0, 0.0, 1.0]),
        ("x".to_string(), nodes.iter().map(|p| p.x).collect()),
    ];
    let f = SimField::from_parts(nodes, tets, cols).unwrap();
    assert_eq!(f.variable_names(), ["dx", "dy", "dz", "len"]);
    assert_eq!((f.node_count(), f.tet_count()), (5, 2));
    assert!(
        f.warnings().iter().any(|w| w.contains("inverted")),
        "{:?}",
        f.warnings()
    );
    assert!(f.boundary_mesh().is_closed_manifold(), "{:?}", f.warnings());
    assert_eq!(f.boundary_mesh().triangle_count(), 6);
    let mut out = [0.0; 4];
    // Midpoint of nodes 1 and 2: dx = 1.5, dy = 2, len = 2.5.
    assert!(f.sample(DVec3::new(0.5, 0.5, 0.0), &mut out));
    assert!((out[0] - 1.5).abs() < 1e-12 && (out[1] - 2.0).abs() < 1e-12);
    assert!((out[3] - 2.5).abs() < 1e-12);
    // Inside the second tet.
    let p = DVec3::new(0.5, 0.5, 0.5) * 0.5 + DVec3::ONE * 0.5 * 0.5 + DVec3::new(0.1, 0.1, 0.1);
    let (t, w) = f.locate(p).unwrap();
    assert_eq!(t, 1);
    assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    assert!(f.signed_distance(p) < 0.0);
    assert!(f.signed_distance(DVec3::splat(2.0)) > 0.0);
    assert!(f.locate(DVec3::new(0.9, 0.9, -0.1)).is_none());
    // A short `out` gets the first variables only.
    let mut short = [0.0; 1];
    assert!(f.sample(DVec3::new(0.5, 0.5, 0.0), &mut short));
    assert!((short[0] - 1.5).abs() < 1e-12);
}

#[test]
fn from_parts_rejects_bad_input() {
    let (nodes, tets) = two_tets();
    let e = SimField::from_parts(nodes.clone(), vec![[0, 1, 2, 7]], vec![]).unwrap_err();
    assert!(e.to_string().contains("node 7"), "{e}");
    let e = SimField::from_parts(nodes.clone(), tets.clone(), vec![("a".into(), vec![1.0])])
        .unwrap_err();
    assert!(e.to_string().contains("1 values for 5 nodes"), "{e}");
    let e =
        SimField::from_parts(nodes.clone(), vec![[0, 1, 2, 3], [0, 1, 2, 0]], vec![]).unwrap_err();
    assert!(
        e.to_string()
            .contains("tet 1 is degenerate: volume 0 mm³ (typical "),
        "{e}"
    );
    let e = SimField::from_parts(nodes, vec![], vec![]).unwrap_err();
    assert!(matches!(e, SimFieldError::Parts { .. }));
}

const TINY_INP: &str = "\
** two tets, ids out of order
*Heading
 tiny
*Node, nset=all
10, 0, 0, 0
2, 1, 0, 0
3, 0, 1, 0
4, 0, 0, 1
5, 1, 1, 1
*ELEMENT, TYPE=C3D8R, ELSET=bricks
99, 10, 2, 3, 4, 5, 10, 2,
    3
*element, type=c3d4, elset=tets
1, 10, 2, 3, 4
2, 5, 2,
 3, 4
*NSET, NSET=fixed
10, 2
*STEP
*STATIC
*END STEP
";

fn write(name: &str, text: &str) -> PathBuf {
    let p = temp_path(name);
    std::fs::write(&p, text).unwrap();
    p
}

const TINY_CSV: &str = "node_id, x, y, z, dx, dy, dz, \"S.Mises\"\n\
5,1,1,1,1,1,1,9\n10,0,0,0,0,0,0,1\n2,1,0,0,3,0,0,2\n3,0,1,0,0,4,0,3\n4,0,0,1,0,0,0,4\n";

#[test]
fn tiny_deck_ids_continuations_and_skipped_types() {
    let inp = write("tiny.inp", TINY_INP);
    let csv = write("tiny.csv", TINY_CSV);
    let f = SimField::load(&inp, &csv).unwrap();
    assert_eq!((f.node_count(), f.tet_count()), (5, 2));
    assert_eq!(f.variable_names(), ["dx", "dy", "dz", "S_Mises", "len"]);
    let w = f.warnings();
    assert!(w.iter().any(|w| w.contains("C3D8R")), "{w:?}");
    assert!(w.iter().any(|w| w.contains("S_Mises")), "{w:?}");
    let mut out = [0.0; 5];
    assert!(f.sample(DVec3::new(0.5, 0.5, 0.0), &mut out));
    assert!(
        (out[3] - 2.5).abs() < 1e-12 && (out[4] - 2.5).abs() < 1e-12,
        "{out:?}"
    );
    for p in [inp, csv] {
        let _ = std::fs::remove_file(p);
    }
}

/// A field with `n` value columns `c0, c1, ...` (besides x, y, z), each
/// linear in x, and dx, dy, dz when `with_len`.
fn wide_csv(n: usize) -> String {
    let ids = [5, 10, 2, 3, 4];
    let xs = [1.0, 0.0, 1.0, 0.0, 0.0];
    let mut text = String::from("node_id,x");
    for k in 0..n {
        text += &format!(",c{k}");
    }
    text += "\n";
    for (id, x) in ids.iter().zip(xs) {
        text += &format!("{id},{x}");
        for k in 0..n {
            text += &format!(",{}", x * k as f64);
        }
        text += "\n";
    }
    text
}

#[test]
fn too_many_columns_is_an_error_not_a_panic() {
    // 54 value columns load and sample (with the nine coordinates, 63 slots).
    let inp = write("wide.inp", TINY_INP);
    let csv = write("wide.csv", &wide_csv(54));
    let f = SimField::load(&inp, &csv).unwrap();
    assert_eq!(f.variable_count(), 54);
    let mut out = vec![0.0; 54];
    assert!(f.sample(DVec3::new(0.2, 0.2, 0.2), &mut out));
    assert!((out[53] - 0.2 * 53.0).abs() < 1e-9, "{}", out[53]);
    for p in [inp, csv] {
        let _ = std::fs::remove_file(p);
    }
    // 55 are refused, naming the header's line.
    expect_error(
        TINY_INP,
        &wide_csv(55),
        Some(("csv", 1)),
        "55 value columns besides the node id and x, y, z; at most 54",
    );
    let (nodes, tets) = two_tets();
    let columns = (0..55)
        .map(|k| (format!("c{k}"), vec![0.0; nodes.len()]))
        .collect();
    let e = SimField::from_parts(nodes, tets, columns).unwrap_err();
    assert!(e.to_string().contains("55 value columns"), "{e}");
}

/// Asserts that loading fails with a message containing `what` (and the
/// file:line prefix when `line` is given).
fn expect_error(inp_text: &str, csv_text: &str, line: Option<(&str, usize)>, what: &str) {
    let inp = write("case.inp", inp_text);
    let csv = write("case.csv", csv_text);
    let e = SimField::load(&inp, &csv).unwrap_err().to_string();
    assert!(e.contains(what), "{e}");
    if let Some((file, l)) = line {
        let path = if file == "inp" { &inp } else { &csv };
        assert!(e.contains(&format!("{}:{l}:", path.display())), "{e}");
    }
    for p in [inp, csv] {
        let _ = std::fs::remove_file(p);
    }
}

#[test]
fn errors_name_file_and_line() {
    let good_csv = TINY_CSV;
    // Missing node row.
    let missing = good_csv.replace("3,0,1,0,0,4,0,3\n", "");
    expect_error(
        TINY_INP,
        &missing,
        None,
        "no row for node 3 (defined at .inp line 7)",
    );
    // Unknown node id.
    let unknown = good_csv.replace("3,0,1,0", "33,0,1,0");
    expect_error(
        TINY_INP,
        &unknown,
        Some(("csv", 5)),
        "node 33 is not in the mesh",
    );
    // Broken number.
    let broken = good_csv.replace("0,4,0,3", "0,4,zero,3");
    expect_error(TINY_INP, &broken, Some(("csv", 5)), "column `dz`: `zero`");
    // Duplicate row.
    let dup = format!("{good_csv}2,1,0,0,3,0,0,2\n");
    expect_error(
        TINY_INP,
        &dup,
        Some(("csv", 7)),
        "node 2 already has a row at line 4",
    );
    // Headerless row count mismatch.
    let rows = "0,0,0,0,0,0\n1,0,0,0,0,0\n0,1,0,0,0,0\n0,0,1,0,0,0\n";
    expect_error(
        TINY_INP,
        rows,
        Some(("csv", 4)),
        "4 data rows for 5 mesh nodes",
    );
    // Headerless wrong column count.
    let seven = "0,0,0,0,0,0,0\n".repeat(5);
    expect_error(TINY_INP, &seven, Some(("csv", 1)), "expected 6 numbers");
    // Degenerate tet (node 4 moved into the plane of 10, 2, 3).
    let flat = TINY_INP.replace("4, 0, 0, 1\n", "4, 0.3, 0.3, 0\n");
    expect_error(
        &flat,
        good_csv,
        Some(("inp", 14)),
        "element 1 is degenerate",
    );
    // Element with an undefined node.
    let undefined = TINY_INP.replace("1, 10, 2, 3, 4", "1, 10, 2, 3, 44");
    expect_error(&undefined, good_csv, Some(("inp", 14)), "refers to node 44");
    // Broken node coordinate.
    let bad_node = TINY_INP.replace("3, 0, 1, 0", "3, 0, 1e, 0");
    expect_error(
        &bad_node,
        good_csv,
        Some(("inp", 7)),
        "`1e` is not a finite number",
    );
    // Wrong element field count.
    let short = TINY_INP.replace("1, 10, 2, 3, 4", "1, 10, 2, 3");
    expect_error(
        &short,
        good_csv,
        Some(("inp", 14)),
        "expected an element line",
    );
    // No tetrahedra at all.
    let no_tets = TINY_INP.replace("type=c3d4", "type=S3");
    expect_error(&no_tets, good_csv, None, "no tetrahedral elements");
    // Missing file.
    let e = SimField::load(&temp_path("none.inp"), &temp_path("none.csv")).unwrap_err();
    assert!(matches!(e, SimFieldError::Io { .. }), "{e}");
}

/// Sampling throughput on the seat at interior points (release build):
/// `cargo test -p volcad-core --release --lib simfield::tests::perf -- --ignored --nocapture`
#[test]
#[ignore]
fn perf_seat_sample() {
    // Build time: parse, tet BVH, boundary mesh and its grids.
    let t = std::time::Instant::now();
    let f = SimField::load(&seat("seat.inp"), &seat("seat_displacement.csv")).unwrap();
    println!(
        "seat load and build (.inp + .csv, all threads): {:.3} s",
        t.elapsed().as_secs_f64()
    );
    let mut rng = Rng::new(3);
    let mut out = [0.0; 4];
    let mut pts = Vec::new();
    while pts.len() < 1_000_000 {
        let p = rng.in_box(&f.bbox());
        if f.locate(p).is_some() {
            pts.push(p);
        }
    }
    // A voxel grid in scan order, as a sampler visits it.
    let b = f.bbox();
    let h = 0.5;
    let n = (b.size() / h).ceil().as_uvec3();
    let mut all = Vec::new();
    for k in 0..n.z {
        for j in 0..n.y {
            for i in 0..n.x {
                all.push(b.min + (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * h);
            }
        }
    }
    let grid: Vec<DVec3> = all
        .iter()
        .copied()
        .filter(|&p| f.locate(p).is_some())
        .collect();
    for (name, pts) in [
        ("random interior", &pts),
        ("voxel-grid interior", &grid),
        ("voxel-grid whole box", &all),
    ] {
        throughput(&format!("seat sample, {name}"), pts, |p| {
            f.sample(p, &mut out);
            out[3]
        });
    }
}

#[test]
fn degenerate_volumes_read_as_millimetres_cubed() {
    use super::volume_text;
    assert_eq!(volume_text(&0.0), "0 mm³");
    assert_eq!(volume_text(&13.135351889496327), "13.14 mm³");
    assert_eq!(volume_text(&0.0025), "0.002500 mm³");
    assert_eq!(volume_text(&123456.7), "123457 mm³");
    assert_eq!(volume_text(&2.5e-12), "2.500e-12 mm³");
    assert_eq!(volume_text(&-0.5), "-0.5000 mm³");
}
