//! How two labels meet: where the contourer cuts a grid edge whose ends
//! carry different labels (see [`super::contour`]'s method), and which of
//! the two labels' meshes faces the other.

/// The 8 samples of one cube.
pub(super) struct Cube<'a> {
    pub base: [usize; 3],
    pub label: [u16; 8],
    pub dist: [f32; 8],
    pub value: [&'a [f32]; 8],
}

/// How an edge between two inside samples of different labels is cut.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Interface {
    /// At the middle (labels only; no values).
    Midpoint,
    /// One value per sample in `[0, 1]`, labels `s + 1` for range
    /// `[s/n, (s+1)/n)`: cut where the value meets the range boundary.
    Ranges {
        /// Number of ranges.
        n: usize,
    },
    /// `k` fractions per sample, label `s + 1` = slot `s` dominant: cut
    /// where the two dominant fractions are equal.
    Dominant {
        /// Fractions per sample.
        k: usize,
    },
}

impl Interface {
    /// Values stored per sample.
    pub fn stride(&self) -> usize {
        match *self {
            Interface::Midpoint => 0,
            Interface::Ranges { .. } => 1,
            Interface::Dominant { k } => k,
        }
    }
}

/// The two labels of an interface in contouring order: `x`, whose
/// triangles face `y`, is the non-void one, or the lower of two segments.
pub(super) fn front_back(a: u16, b: u16) -> (u16, u16) {
    if a == 0 || (b != 0 && b < a) {
        (b, a)
    } else {
        (a, b)
    }
}

/// The field whose zero cuts edges between labels `la` and `lb`, at a
/// sample with distance `d` and interface values `f` (the distance next to
/// void, `f − c` at the range boundary `c`, `f_lb − f_la` for dominant
/// materials); `None` for [`Interface::Midpoint`] between segments. With
/// `(la, lb)` from [`front_back`] it is negative on `la`'s side. Inlined:
/// called twice for every vertex placed, where the first test decides.
#[inline]
pub(super) fn cut_field(iface: Interface, la: u16, lb: u16, d: f32, f: &[f32]) -> Option<f64> {
    if la == 0 || lb == 0 {
        return Some(f64::from(d));
    }
    match iface {
        Interface::Midpoint => None,
        Interface::Ranges { n } => Some(f64::from(f[0]) - f64::from(la + lb - 1) / (2 * n) as f64),
        Interface::Dominant { .. } => {
            Some(f64::from(f[lb as usize - 1]) - f64::from(f[la as usize - 1]))
        }
    }
}

/// The corners of `cube` labelled `label`, as bits.
pub(super) fn corner_mask(cube: &Cube, label: u16) -> u8 {
    (0..8).fold(0, |m, c| m | u8::from(cube.label[c] == label) << c)
}
