//! The top union's one-walk path (`hint`) gives what the attribute tree's
//! own search gives, and `eval_with_attributes` what `eval_into` and
//! `attribute_at` give.

use glam::DVec3;

use super::tests::model;
use crate::Model;

/// Attribute `idx` at `p` by the attribute tree's own search (no hint).
fn searched(m: &Model, idx: usize, p: DVec3, out: &mut [f64]) {
    let a = m.attrs.as_ref().expect("attributes");
    let found = m.root.contains(p) && a.root.eval(idx, p, p, out).expect("value");
    if !found {
        out.fill(f64::NAN);
    }
}

fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

/// Every attribute on a grid of points over the design's box: the hinted,
/// searched and one-walk results agree bit for bit; returns how many
/// values were found (not NaN).
fn agree(m: &Model) -> usize {
    let k = m.materials().len();
    let b = m.bbox();
    let n = 24;
    let mut found = 0;
    let all: Vec<usize> = (0..m.attributes().len()).collect();
    let width: usize = m.attributes().iter().map(|a| a.kind.width()).sum();
    let pts: Vec<DVec3> = (0..n * n * n)
        .map(|i| {
            let t = DVec3::new(
                (i % n) as f64 + 0.37,
                (i / n % n) as f64 + 0.61,
                (i / (n * n)) as f64 + 0.23,
            ) / n as f64;
            b.min + (b.max - b.min) * t
        })
        .collect();
    batch_agrees(m, &pts, &all);
    for &p in &pts {
        let mut f = vec![0.0; k];
        let d = m.eval_into(p, &mut f);
        let mut f2 = vec![0.0; k];
        let mut v = vec![0.0; width];
        let d2 = m.eval_with_attributes(p, &mut f2, &all, &mut v).unwrap();
        assert!(same(d, d2), "{p}");
        assert_eq!(f, f2, "{p}");
        let mut at = 0;
        for (idx, info) in m.attributes().iter().enumerate() {
            let w = info.kind.width();
            let (mut hinted, mut reference) = ([0.0; 4], [0.0; 4]);
            m.attribute_at(idx, p, &mut hinted[..w]).unwrap();
            searched(m, idx, p, &mut reference[..w]);
            for c in 0..w {
                assert!(
                    same(hinted[c], reference[c]) && same(v[at + c], reference[c]),
                    "{} at {p}: hinted {}, one walk {}, searched {}",
                    info.name,
                    hinted[c],
                    v[at + c],
                    reference[c]
                );
                found += usize::from(!reference[c].is_nan());
            }
            at += w;
        }
    }
    found
}

/// `eval_with_attributes_batch` gives what `eval_with_attributes` gives
/// point by point, bit for bit.
fn batch_agrees(m: &Model, pts: &[DVec3], wanted: &[usize]) {
    let k = m.materials().len();
    let width: usize = wanted.iter().map(|&i| m.attributes()[i].kind.width()).sum();
    let (mut d, mut f, mut v) = (
        vec![0.0; pts.len()],
        vec![0.0; k * pts.len()],
        vec![0.0; width * pts.len()],
    );
    m.eval_with_attributes_batch(pts, &mut d, &mut f, wanted, &mut v)
        .unwrap();
    let (mut f1, mut v1) = (vec![0.0; k], vec![0.0; width]);
    for (i, p) in pts.iter().enumerate() {
        let d1 = m
            .eval_with_attributes(*p, &mut f1, wanted, &mut v1)
            .unwrap();
        assert!(same(d1, d[i]), "{p}");
        assert_eq!(f1, f[i * k..(i + 1) * k], "{p}");
        for (a, b) in v1.iter().zip(&v[i * width..(i + 1) * width]) {
            assert!(same(*a, *b), "{p}: one point {a}, batch {b}");
        }
    }
}

/// [`agree`] on the design `src`, whose top union must hand over the
/// child it found.
fn hinted(src: &str) -> usize {
    let m = model(src);
    assert!(m.attrs.as_ref().unwrap().hint.is_some(), "{src}");
    agree(&m)
}

/// 30 overlapping spheres, each with its index as `temperature`, some
/// without one, in a union at the top.
const SPHERES: &str = "let u = Union(); for i in 0..30 { let s = Sphere(Vec3(1.5 * i, 0, 0), 1.0, m.id(\"red\")); if i % 4 != 3 { s.set_attribute(\"temperature\", 1.0 * i); } u.add_child(s); }";

#[test]
fn the_top_union_hands_over_the_child_it_found() {
    // Children with the attribute, without it, and a plain box after them
    // (the bunny lattice's clear body).
    assert!(
        hinted(&format!(
            "{SPHERES} u.add_child(RectPrism(Vec3(20, 0, 0), Vec3(50, 3, 3), m.id(\"blue\"))); u"
        )) > 1000
    );
}

#[test]
fn a_later_child_still_gives_its_value() {
    // A plain box comes first: where it holds a point, a child after it
    // that holds the point too gives the value (moved children, a colour).
    assert!(hinted("let u = Union(); u.add_child(RectPrism(Vec3(20, 0, 0), Vec3(50, 3, 3), m.id(\"blue\")));
         for i in 0..30 { let s = Sphere(Vec3(1.5 * i, 0, 0), 1.0, m.id(\"red\")); if i % 4 != 3 { s.set_attribute(\"temperature\", 1.0 * i); } u.add_child(s); }
         for c in 0..3 { let s = Sphere(Vec3(10.0 * c, 0, 0), 2.0, m.id(\"green\")); s.set_attribute(\"temperature\", 100.0 + c); s.set_attribute(\"color\", Vec4(0.1 * c, 0.5, 0.5, 1.0)); u.add_child(Translate(1.0, 0.0, 0.0, s)); }
         u",) > 500);
    // A nested union is spliced into the top one: its children's run of
    // the top union's children hands over the nested union.
    assert!(
        hinted(&format!(
            "let b = RectPrism(Vec3(20, 0, 0), Vec3(50, 3, 3), m.id(\"blue\")); {SPHERES} let w = Union(); w.add_child(b); w.add_child(u); w"
        )) > 500
    );
}

#[test]
fn a_union_graded_as_a_whole_is_handed_over() {
    // The bunny lattice graded by one `set_attribute` on its union, a body
    // after it: the graded union stays one child of the top union.
    let lattice = "let l = Union(); for i in 0..30 { l.add_child(Sphere(Vec3(1.5 * i, 0, 0), 1.0, m.id(\"red\"))); } l.set_attribute(\"temperature\", \"20 + x\");";
    let body = "RectPrism(Vec3(20, 0, 0), Vec3(50, 3, 3), m.id(\"blue\"))";
    assert!(hinted(&format!("{lattice} Union(false, [l, {body}])")) > 1000);
    // Body first, then two graded runs (a later run still gives its value).
    assert!(
        hinted(&format!(
            "{lattice} let l2 = Union(); for i in 0..5 {{ l2.add_child(Sphere(Vec3(3.0 * i, 1, 0), 1.5, m.id(\"green\"))); }} l2.set_attribute(\"temperature\", 7.0); Union(false, [{body}, l, l2])"
        )) > 1000
    );
}

#[test]
fn a_graded_union_kept_whole_gives_the_distance_and_fractions_of_the_plain_one() {
    // The graded union is not spliced into the top union and its one
    // material is read without a search: bit for bit what the plain
    // (spliced) design gives.
    let lattice = "let l = Union(); for i in 0..30 { l.add_child(Sphere(Vec3(1.5 * i, 0.1 * i, 0), 1.0, m.id(\"red\"))); }";
    let top = "Union(false, [l, RectPrism(Vec3(20, 0, 0), Vec3(50, 3, 3), m.id(\"blue\"))])";
    let plain = model(&format!("{lattice} {top}"));
    let graded = model(&format!(
        "{lattice} l.set_attribute(\"temperature\", \"20 + x\"); {top}"
    ));
    let b = plain.bbox();
    let (mut fa, mut fb) = (vec![0.0; 2], vec![0.0; 2]);
    let mut inside = 0;
    for i in 0..20_000 {
        let t = DVec3::new(
            (i % 40) as f64 / 39.0,
            (i / 40 % 25) as f64 / 24.0,
            (i / 1000) as f64 / 19.0,
        );
        let p = b.min + (b.max - b.min) * t;
        let da = plain.eval_into(p, &mut fa);
        let db = graded.eval_into(p, &mut fb);
        assert_eq!(da.to_bits(), db.to_bits(), "{p}");
        assert!(
            fa.iter().zip(&fb).all(|(x, y)| x.to_bits() == y.to_bits()),
            "{p}: {fa:?} {fb:?}"
        );
        inside += usize::from(da <= 0.0 && fa[0] > 0.0);
    }
    assert!(inside > 500, "{inside}");
}

#[test]
fn a_batch_runs_shared_math_strings_and_refuses_the_first_bad_point() {
    // Per-child strings shared by every child (one tape), a union graded
    // as a whole, an affine string (its own per-point form) and a colour.
    let per_child = "let u = Union(); for i in 0..30 { let s = Sphere(Vec3(1.5 * i, 0, 0), 1.0, m.id(\"red\")); s.set_attribute(\"modulus\", \"500 + 20*clamp(0, x, 40)\"); s.set_attribute(\"temperature\", \"20 + 2*x\"); s.set_attribute(\"color\", Vec4(0.5, 0.5, 0.5, 1.0)); u.add_child(s); } u.add_child(RectPrism(Vec3(20, 0, 0), Vec3(50, 3, 3), m.id(\"blue\"))); u";
    assert!(agree(&model(per_child)) > 1000);
    // A modulus that turns negative: the batch names the first such point
    // in order, as one point at a time does.
    let bad = model(
        "let l = Union(); for i in 0..30 { l.add_child(Sphere(Vec3(1.5 * i, 0, 0), 1.0, m.id(\"red\"))); } l.set_attribute(\"modulus\", \"100 - 5*abs(x - 10)\"); Union(false, [l, RectPrism(Vec3(60, 0, 0), Vec3(2, 2, 2), m.id(\"blue\"))])",
    );
    let pts: Vec<DVec3> = (0..400)
        .map(|i| DVec3::new(0.11 * i as f64, 0.1, 0.0))
        .collect();
    let k = bad.materials().len();
    let (mut d, mut f, mut v) = (vec![0.0; 400], vec![0.0; 400 * k], vec![0.0; 400]);
    let e = bad
        .eval_with_attributes_batch(&pts, &mut d, &mut f, &[0], &mut v)
        .unwrap_err();
    let first = pts
        .iter()
        .find_map(|p| {
            bad.eval_with_attributes(*p, &mut vec![0.0; k], &[0], &mut [0.0])
                .err()
        })
        .unwrap();
    assert_eq!(e.message, first.message);
    assert!(e.message.contains("modulus"), "{}", e.message);
    // Buffers of the wrong size are refused before any work.
    let e = bad
        .eval_with_attributes_batch(&pts, &mut d, &mut f, &[0], &mut v[..10])
        .unwrap_err();
    assert!(e.message.contains("the buffer has 10"), "{}", e.message);
}

#[test]
fn resolvers_parents_and_other_tops_search_as_before() {
    for src in [
        format!("{SPHERES} u.set_attribute_conflict_resolver(\"temperature\", \"max\"); u"),
        format!("{SPHERES} u.set_attribute(\"temperature\", \"100 + x\"); u"),
        format!("{SPHERES} Translate(1.0, 2.0, 0.0, u)"),
        format!("{SPHERES} Union(1.0, false, [u, Sphere(Vec3(0, 3, 0), 2.0, m.id(\"blue\"))])"),
    ] {
        let m = model(&src);
        assert!(agree(&m) > 500, "{src}");
    }
}

#[test]
fn one_math_string_on_many_nodes_is_compiled_once() {
    use super::prepared::{Op, OwnSrc, PComp};
    let m = model(
        "let u = Union(); for i in 0..20 { let s = Sphere(Vec3(3.0 * i, 0, 0), 1.0, m.id(\"red\")); s.set_attribute(\"t\", \"x + d\"); u.add_child(s); }
         let other = Sphere(Vec3(0, 5, 0), 1.0, m.id(\"red\")); other.set_attribute(\"t\", \"x + d\"); other.set_attribute(\"w\", 2.0); u.add_child(other); u",
    );
    let root = &m.attrs.as_ref().unwrap().root;
    let Op::Pick { children, .. } = &root.op else {
        panic!("a union");
    };
    let tape = |k: usize| match &children[k].own[0].src {
        OwnSrc::Comps(cs) => match &cs[0] {
            PComp::Expr(e) => e.clone(),
            PComp::Const(_) => panic!("a math string"),
        },
        _ => panic!("components"),
    };
    for k in 1..20 {
        assert!(std::sync::Arc::ptr_eq(&tape(0), &tape(k)), "{k}");
    }
    // Another variable list (the node also sets "w") compiles its own.
    assert!(!std::sync::Arc::ptr_eq(&tape(0), &tape(20)));
    assert!(agree(&m) > 100);
}

#[test]
fn the_pick_grid_lists_every_child_that_may_hold_a_point() {
    use super::prepared::Op;
    // 60 long diagonal struts crossing each other (their boxes meet many
    // cells they do not pass through), in a union under a move, so the
    // search uses the grid: its answer is the first child holding the
    // point, found by testing every child.
    let m = model(
        "let u = Union(); for i in 0..60 { let a = Vec3(0.7 * i, 0.0, 0.3 * i); let b = Vec3(40.0 - 0.5 * i, 25.0, 0.2 * i + 5.0); let s = Strut(a, b, 0.8, m.id(\"red\")); s.set_attribute(\"temperature\", 1.0 * i); u.add_child(s); } Translate(0.5, 0.0, 0.0, u)",
    );
    let a = m.attrs.as_ref().unwrap();
    let Op::Map(_, u) = &a.root.op else {
        panic!("a move");
    };
    let Op::Pick { children, grid, .. } = &u.op else {
        panic!("a union");
    };
    assert!(grid.is_some());
    let b = m.bbox();
    let n = 40;
    let mut held = 0;
    for i in 0..n * n * n {
        let t = DVec3::new((i % n) as f64, (i / n % n) as f64, (i / (n * n)) as f64) / n as f64;
        let p = b.min + (b.max - b.min) * (t + 0.013);
        let q = p - DVec3::new(0.5, 0.0, 0.0);
        let want = children.iter().position(|c| c.dist.contains(q));
        let mut got = [0.0];
        m.attribute_at(0, p, &mut got).unwrap();
        match want {
            Some(k) => {
                assert_eq!(got[0], k as f64, "{p}");
                held += 1;
            }
            None => assert!(got[0].is_nan(), "{p}"),
        }
    }
    assert!(held > 500, "{held}");
}
