//! The combinatorics of the Kuhn split that [`super::contour`] cuts: the six
//! tets of a cube, their faces, the contour's points by the corners they are
//! built from, and how a face with two labels is cut. Corners are bit masks
//! (x = 1, y = 2, z = 4).

/// Axis orders of the six Kuhn tets (tet `π`: corners `0`, `e_π1`,
/// `e_π1 + e_π2`, `(1,1,1)`); the FEA tet lattice splits its cubes the same
/// way.
pub(crate) const PERMS: [[u8; 3]; 6] = [
    [0, 1, 2],
    [0, 2, 1],
    [1, 0, 2],
    [1, 2, 0],
    [2, 0, 1],
    [2, 1, 0],
];
/// Faces of a positively oriented tet (v0..v3), counter-clockwise seen from
/// outside.
pub(super) const FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
/// A point of the contour inside one cube, by the cube corners (bit masks
/// x = 1, y = 2, z = 4) it is built from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Pt {
    /// On the edge between two corners (lower mask first).
    Edge(u8, u8),
    /// Centroid of a three-label face (corners by inclusion).
    Face(u8, u8, u8),
    /// Centroid of the tet's edge points.
    Tet,
}

/// Order corner masks by inclusion (Kuhn corners are nested sets).
pub(super) fn by_inclusion(a: u8, b: u8) -> (u8, u8) {
    if a.count_ones() < b.count_ones() {
        (a, b)
    } else {
        (b, a)
    }
}

pub(super) fn edge(a: u8, b: u8) -> Pt {
    let (a, b) = by_inclusion(a, b);
    Pt::Edge(a, b)
}

/// Corners of Kuhn tet `perm`, positively oriented.
pub(super) fn tet_corners(perm: usize) -> [u8; 4] {
    let [a1, a2, _] = PERMS[perm];
    let m1 = 1u8 << a1;
    let m2 = m1 | 1 << a2;
    // Even axis orders give positively oriented tets; swap for odd ones.
    if matches!(perm, 0 | 3 | 4) {
        [0, m1, m2, 7]
    } else {
        [0, m2, m1, 7]
    }
}

/// On a tet face with corners `[u, w, x]` (counter-clockwise from outside)
/// and two labels: the odd corner `o`, its predecessor `p` and successor
/// `s`, the odd label and the other. `None` with one or three labels.
pub(super) fn odd_one_out(
    [u, w, x]: [u8; 3],
    [lu, lw, lx]: [u16; 3],
) -> Option<(u8, u8, u8, u16, u16)> {
    if lu == lw && lw == lx {
        None
    } else if lu == lw {
        Some((x, w, u, lx, lu))
    } else if lw == lx {
        Some((u, x, w, lu, lw))
    } else if lx == lu {
        Some((w, u, x, lw, lx))
    } else {
        None
    }
}

/// The cut of a two-label tet face (from [`odd_one_out`]) as one oriented
/// segment per label, `(label, from, to)`, with the label's side on the
/// left seen from outside the tet.
pub(super) fn two_label_cut((o, p, s, lo, rest): (u8, u8, u8, u16, u16)) -> [(u16, Pt, Pt); 2] {
    [(lo, edge(p, o), edge(o, s)), (rest, edge(o, s), edge(p, o))]
}

/// Per mask of one label's corners, the faces of the cube the cut crosses
/// that `Contourer::flat_layer` joins or outlines: bit `2·axis + side`
/// for the four faces across x and y and the one below (bit 4; the face
/// above is settled with the next layer). A table, since every flat cube
/// asks, and the five tests in a loop cost more than one lookup.
pub(super) const CUT_FACES: [u8; 256] = {
    let mut t = [0u8; 256];
    let mut m = 0;
    while m < 256 {
        let mut f = 0;
        while f < 5 {
            if face_cut(m as u8, f >> 1, (f & 1) as u8) {
                t[m] |= 1 << f;
            }
            f += 1;
        }
        m += 1;
    }
    t
};

/// Whether the face (`axis`, `side`) of a two-label cube is cut, from the
/// mask of one label's corners.
pub(super) const fn face_cut(mask: u8, axis: usize, side: u8) -> bool {
    // Corners with bit `axis` clear, per axis; the other side is the rest.
    const LOW: [u8; 3] = [0b0101_0101, 0b0011_0011, 0b0000_1111];
    let face = if side == 0 { LOW[axis] } else { !LOW[axis] };
    let m = mask & face;
    m != 0 && m != face
}

/// Join segments `(from, to)` into one closed loop of points in `ring`;
/// false if they do not form exactly one loop.
pub(super) fn chain(segs: &[(Pt, Pt)], ring: &mut Vec<Pt>) -> bool {
    ring.clear();
    let Some(&(first, mut end)) = segs.first() else {
        return false;
    };
    ring.push(first);
    while end != first {
        if ring.len() > segs.len() {
            return false;
        }
        ring.push(end);
        match segs.iter().find(|s| s.0 == end) {
            Some(s) => end = s.1,
            None => return false,
        }
    }
    ring.len() == segs.len() && ring.len() >= 3
}
