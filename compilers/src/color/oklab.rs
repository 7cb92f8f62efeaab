//! Colour conversions into OKLab and the resins' gamut in it.
//!
//! OKLab (B. Ottosson, "A perceptual color space for image processing",
//! 2020): linear sRGB (or CIE XYZ, D65) → LMS by a 3 × 3 matrix, a cube
//! root per channel, and a second 3 × 3 matrix. Euclidean distance in it
//! is a colour difference (ΔE_ok; ×100 is on about the scale of CIELAB's
//! ΔE), and its lines of constant hue stay straight where CIELAB's bend
//! (blue turning purple as chroma falls), which is what gamut clipping
//! toward grey relies on.

/// An OKLab colour: `[L, a, b]`, L from 0 (black) to 1 (white).
pub type Lab = [f64; 3];

/// An sRGB component (0..=1) to linear light (IEC 61966-2-1).
pub fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn mul(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// Ottosson's second matrix: cube-rooted LMS → Lab.
const LMS_TO_LAB: [[f64; 3]; 3] = [
    [0.210_454_255_3, 0.793_617_785_0, -0.004_072_046_8],
    [1.977_998_495_1, -2.428_592_205_0, 0.450_593_709_9],
    [0.025_904_037_1, 0.782_771_766_2, -0.808_675_766_0],
];

fn from_lms(lms: [f64; 3]) -> Lab {
    mul(&LMS_TO_LAB, lms.map(f64::cbrt))
}

/// OKLab of a linear-light sRGB colour.
pub fn from_linear_srgb(rgb: [f64; 3]) -> Lab {
    const M: [[f64; 3]; 3] = [
        [0.412_221_470_8, 0.536_332_536_3, 0.051_445_992_9],
        [0.211_903_498_2, 0.680_699_545_1, 0.107_396_956_6],
        [0.088_302_461_9, 0.281_718_837_6, 0.629_978_700_5],
    ];
    from_lms(mul(&M, rgb))
}

/// OKLab of an sRGB colour with components in 0..=1.
pub fn from_srgb(rgb: [f64; 3]) -> Lab {
    from_linear_srgb(rgb.map(srgb_to_linear))
}

/// OKLab of a CIELAB colour measured under D50 (the ICC profile
/// connection space and what print spectrophotometers report): CIELAB →
/// XYZ (D50 white 0.9642, 1, 0.8252), Bradford adaptation to D65
/// (Lindbloom's matrix), then Ottosson's XYZ → LMS matrix.
pub fn from_cielab_d50(lab: [f64; 3]) -> Lab {
    const D50: [f64; 3] = [0.964_22, 1.0, 0.825_21];
    const BRADFORD_D50_TO_D65: [[f64; 3]; 3] = [
        [0.955_576_6, -0.023_039_3, 0.063_163_6],
        [-0.028_289_5, 1.009_941_6, 0.021_007_7],
        [0.012_298_2, -0.020_483_0, 1.329_909_8],
    ];
    const XYZ_TO_LMS: [[f64; 3]; 3] = [
        [0.818_933_010_1, 0.361_866_742_4, -0.128_859_713_7],
        [0.032_984_543_6, 0.929_311_871_5, 0.036_145_638_7],
        [0.048_200_301_8, 0.264_366_269_1, 0.633_851_707_0],
    ];
    // CIE 15: f⁻¹(t) = t³ above δ = 6/29, linear below.
    let inv = |t: f64| {
        let d = 6.0 / 29.0;
        if t > d {
            t * t * t
        } else {
            3.0 * d * d * (t - 4.0 / 29.0)
        }
    };
    let fy = (lab[0] + 16.0) / 116.0;
    let f = [fy + lab[1] / 500.0, fy, fy - lab[2] / 200.0];
    let xyz50 = [0, 1, 2].map(|i| D50[i] * inv(f[i]));
    let xyz65 = mul(&BRADFORD_D50_TO_D65, xyz50);
    // Negative LMS (impossible colours) would give a negative cube root;
    // cbrt keeps the sign, so the result stays defined.
    from_lms(mul(&XYZ_TO_LMS, xyz65))
}

fn sub(a: Lab, b: Lab) -> Lab {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: Lab, b: Lab) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: Lab, b: Lab) -> Lab {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Distances below this (OKLab units) count as on a plane.
const EPS: f64 = 1e-9;

/// The colours a set of opaque resins can average to: their convex hull in
/// OKLab, as the planes of its faces (`n · p ≤ d` inside, `n` unit).
#[derive(Clone, Debug, PartialEq)]
pub struct Gamut {
    planes: Vec<(Lab, f64)>,
    dark: Lab,
    light: Lab,
}

impl Gamut {
    /// The hull of `points`; `None` when they do not span a volume (fewer
    /// than four resins, or all in one plane), where no clipping is done.
    pub fn new(points: &[Lab]) -> Option<Gamut> {
        let n = points.len();
        let mut planes = Vec::new();
        // A few resins: every triple is a candidate face (O(n⁴), n ≤ 16).
        for i in 0..n {
            for j in i + 1..n {
                for k in j + 1..n {
                    let (p, q, r) = (points[i], points[j], points[k]);
                    let nrm = cross(sub(q, p), sub(r, p));
                    let len = dot(nrm, nrm).sqrt();
                    if len < EPS {
                        continue;
                    }
                    let nrm = nrm.map(|c| c / len);
                    let sides: Vec<f64> = points.iter().map(|x| dot(nrm, sub(*x, p))).collect();
                    if sides.iter().all(|s| *s <= EPS) {
                        planes.push((nrm, dot(nrm, p)));
                    } else if sides.iter().all(|s| *s >= -EPS) {
                        let neg = nrm.map(|c| -c);
                        planes.push((neg, dot(neg, p)));
                    }
                }
            }
        }
        // A flat set has its plane twice (both orientations): no volume.
        let flat = planes.iter().any(|(a, d)| {
            planes
                .iter()
                .any(|(b, e)| dot(*a, *b) < -1.0 + EPS && (d + e).abs() < EPS)
        });
        if planes.is_empty() || flat {
            return None;
        }
        let by_l = |a: &&Lab, b: &&Lab| a[0].total_cmp(&b[0]);
        let dark = *points.iter().min_by(by_l)?;
        let light = *points.iter().max_by(by_l)?;
        Some(Gamut {
            planes,
            dark,
            light,
        })
    }

    /// True when `p` lies in the hull.
    pub fn contains(&self, p: Lab) -> bool {
        self.planes.iter().all(|(n, d)| dot(*n, p) <= d + EPS)
    }

    /// `p` if it is in the hull, else the hull's point on the line from
    /// `p` toward the grey of its lightness (the point of the darkest–
    /// lightest resin segment with `p`'s L, clamped to its ends): chroma
    /// is reduced at constant hue, the usual clipping toward the neutral
    /// axis, so an out-of-gamut colour keeps its hue and lightness as far
    /// as the resins allow.
    pub fn map(&self, p: Lab) -> Lab {
        if self.contains(p) {
            return p;
        }
        let span = self.light[0] - self.dark[0];
        let t = if span > EPS {
            ((p[0] - self.dark[0]) / span).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let c = [0, 1, 2].map(|i| self.dark[i] + t * (self.light[i] - self.dark[i]));
        let dir = sub(p, c);
        let mut s: f64 = 1.0;
        for (n, d) in &self.planes {
            let along = dot(*n, dir);
            if along > EPS {
                s = s.min((d - dot(*n, c)) / along);
            }
        }
        let s = s.clamp(0.0, 1.0);
        [0, 1, 2].map(|i| c[i] + s * dir[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Lab, b: Lab, tol: f64) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < tol)
    }

    #[test]
    fn reference_values() {
        // Ottosson's published values for sRGB white and red.
        assert!(close(from_srgb([1.0, 1.0, 1.0]), [1.0, 0.0, 0.0], 1e-4));
        let red = from_srgb([1.0, 0.0, 0.0]);
        assert!(
            close(red, [0.627_955, 0.224_863, 0.125_846], 1e-4),
            "{red:?}"
        );
        // D50 white in CIELAB adapts to D65 white; sRGB red is CIELAB
        // (D50) 54.29, 80.80, 69.89 (Lindbloom's calculator).
        let w = from_cielab_d50([100.0, 0.0, 0.0]);
        assert!(close(w, [1.0, 0.0, 0.0], 2e-3), "{w:?}");
        let r = from_cielab_d50([54.29, 80.80, 69.89]);
        assert!(close(r, red, 5e-3), "{r:?}");
    }

    #[test]
    fn gamut_keeps_inside_colours_and_clips_toward_grey() {
        let cmykw = [
            [0.0, 1.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 1.0],
        ]
        .map(from_srgb);
        let g = Gamut::new(&cmykw).unwrap();
        let grey = from_srgb([0.5, 0.5, 0.5]);
        assert_eq!(g.map(grey), grey);
        for c in &cmykw {
            assert!(g.contains(*c));
        }
        let red = from_srgb([1.0, 0.0, 0.0]);
        assert!(
            !g.contains(red),
            "sRGB red lies outside what CMYKW average to"
        );
        let m = g.map(red);
        assert!(g.contains(m));
        // Same hue, less chroma.
        let hue = |p: Lab| p[2].atan2(p[1]);
        assert!((hue(m) - hue(red)).abs() < 0.05, "{m:?}");
        assert!(m[1].hypot(m[2]) < red[1].hypot(red[2]));
        assert!(
            Gamut::new(&cmykw[3..]).is_none(),
            "black and white span no volume"
        );
    }
}
