//! Text as 2D outlines: pyvcad's `Text` layout (OpenCASCADE's
//! `Font_TextFormatter` as pyvcad 2.3.4 drives it) over glyph outlines read
//! with ttf-parser, curves flattened to polygons.
//!
//! Layout, in millimetres with y up (the text reads along +x seen from +z):
//! the font size (em) is `height`; line `i` has its baseline at
//! `−ascender − i·line_spacing` (hhea ascender, and spacing = ascender −
//! descender + line gap); each line is aligned by its advance width (`Left`
//! starts at x = 0, `Right` ends there, `Center` straddles it); the block
//! is then moved up by 0 (`Top`: the first line's ascender at y = 0), the
//! ascender (`Top_First_Line`: first baseline at 0), half the lines'
//! spacing (`Center`) or the ascender plus all but one spacing (`Bottom`:
//! last baseline at 0). Advances include the font's kerning pairs (the
//! `kern` table, else the pair adjustments of GPOS's `kern` feature).

mod font;
mod kerning;

use glam::DVec2;
use ttf_parser::OutlineBuilder;

/// Curves are flattened to within this fraction of the text height
/// (Wang's bound on the chord error of uniformly split Béziers): 5 µm for a
/// 10 mm label, a fifth of the thinnest inkjet layer, so the polygon's
/// distance is the font's to well within a voxel.
pub(crate) const FLATTEN_TOLERANCE: f64 = 5e-4;

/// Most characters one `Text` node lays out.
pub const MAX_CHARS: usize = 10_000;

/// pyvcad's `FontAspect`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FontAspect {
    /// Upright, normal weight.
    Regular,
    /// Upright, bold weight.
    Bold,
    /// Slanted (italic or oblique), normal weight.
    Italic,
    /// Slanted, bold weight.
    BoldItalic,
}

impl FontAspect {
    /// The pyvcad member name.
    pub fn name(self) -> &'static str {
        match self {
            FontAspect::Regular => "Regular",
            FontAspect::Bold => "Bold",
            FontAspect::Italic => "Italic",
            FontAspect::BoldItalic => "BoldItalic",
        }
    }
}

/// pyvcad's `HorizontalAlignment`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum HorizontalAlignment {
    /// Each line starts at x = 0.
    Left,
    /// Each line is centred on x = 0.
    Center,
    /// Each line ends at x = 0.
    Right,
}

/// pyvcad's `VerticalAlignment`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[allow(non_camel_case_types)]
pub enum VerticalAlignment {
    /// The last line's baseline at y = 0.
    Bottom,
    /// The lines' block (line spacings) centred on y = 0.
    Center,
    /// The first line's ascender at y = 0.
    Top,
    /// The first line's baseline at y = 0.
    Top_First_Line,
}

/// How to set a text.
#[derive(Clone, Debug)]
pub struct TextStyle {
    /// Font size (em), mm.
    pub height: f64,
    /// Weight and slant.
    pub aspect: FontAspect,
    /// Family name, e.g. "DejaVu Sans".
    pub font: String,
    /// Where each line sits along x.
    pub h_align: HorizontalAlignment,
    /// Where the block of lines sits along y.
    pub v_align: VerticalAlignment,
}

/// A laid-out text.
#[derive(Clone, Debug)]
pub struct TextOutline {
    /// Closed contours (mm; fill by the non-zero rule).
    pub contours: Vec<Vec<DVec2>>,
    /// The family the glyphs came from.
    pub family: String,
    /// Each line's advance width (kerning included), mm.
    pub line_widths: Vec<f64>,
    /// Each line's baseline height after alignment, mm.
    pub baselines: Vec<f64>,
    /// Font fallbacks and missing glyphs.
    pub warnings: Vec<String>,
}

/// Why a text could not be laid out.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TextError {
    /// The text has no characters.
    #[error("the text is empty; give at least one character")]
    Empty,
    /// More than [`MAX_CHARS`] characters.
    #[error(
        "the text has {chars} characters; at most {MAX_CHARS} fit in one Text (split it into several)"
    )]
    TooLong {
        /// Characters in the text.
        chars: usize,
    },
    /// The height is not a positive number.
    #[error("height must be > 0, got {0}")]
    Height(f64),
    /// The font's data could not be used.
    #[error("{0}")]
    Font(String),
    /// No character of the text has a visible glyph.
    #[error("{text:?} has no visible glyph in {family}; give letters, digits or symbols")]
    NoGlyph {
        /// The text.
        text: String,
        /// The font family used.
        family: String,
    },
}

/// Lay out `text` and flatten its glyphs. Errors: empty text, too long, a
/// non-positive height, an unreadable font, no visible glyph.
pub fn outline(text: &str, style: &TextStyle) -> Result<TextOutline, TextError> {
    if text.is_empty() {
        return Err(TextError::Empty);
    }
    let chars = text.chars().count();
    if chars > MAX_CHARS {
        return Err(TextError::TooLong { chars });
    }
    if !(style.height.is_finite() && style.height > 0.0) {
        return Err(TextError::Height(style.height));
    }
    let mut warnings = Vec::new();
    let out = font::with_font(&style.font, style.aspect, &mut warnings, |face, family| {
        layout(face, family, text, style)
    })
    .and_then(|laid| laid)
    .map_err(TextError::Font)?;
    warnings.extend(out.warnings);
    if out.contours.is_empty() {
        return Err(TextError::NoGlyph {
            text: text.to_owned(),
            family: out.family,
        });
    }
    Ok(TextOutline { warnings, ..out })
}

fn layout(
    face: &ttf_parser::Face<'_>,
    family: &str,
    text: &str,
    style: &TextStyle,
) -> Result<TextOutline, String> {
    let upem = f64::from(face.units_per_em());
    if upem <= 0.0 {
        return Err(format!("font \"{family}\" has no units per em"));
    }
    let scale = style.height / upem;
    let asc = f64::from(face.ascender()) * scale;
    let spacing = f64::from(face.ascender() - face.descender() + face.line_gap()) * scale;
    let lines: Vec<&str> = text.split('\n').collect();
    let shift = match style.v_align {
        VerticalAlignment::Top => 0.0,
        VerticalAlignment::Top_First_Line => asc,
        VerticalAlignment::Center => 0.5 * spacing * lines.len() as f64,
        VerticalAlignment::Bottom => asc + spacing * (lines.len() - 1) as f64,
    };
    let kern = kerning::Kerning::new(face);
    let tolerance = style.height * FLATTEN_TOLERANCE;
    let mut missing: Vec<char> = Vec::new();
    let mut out = TextOutline {
        contours: Vec::new(),
        family: family.to_owned(),
        line_widths: Vec::new(),
        baselines: Vec::new(),
        warnings: Vec::new(),
    };
    let space = face
        .glyph_index(' ')
        .and_then(|g| face.glyph_hor_advance(g))
        .map_or(0.0, |a| f64::from(a) * scale);
    for (i, line) in lines.iter().enumerate() {
        let baseline = shift - asc - spacing * i as f64;
        // Glyphs and pen positions first: alignment needs the line's width.
        let mut placed: Vec<(ttf_parser::GlyphId, f64)> = Vec::new();
        let mut pen = 0.0;
        let mut prev: Option<ttf_parser::GlyphId> = None;
        for ch in line.chars().filter(|c| *c != '\r') {
            if ch == '\t' {
                pen += 4.0 * space;
                prev = None;
                continue;
            }
            let gid = face.glyph_index(ch).unwrap_or_else(|| {
                if !missing.contains(&ch) {
                    missing.push(ch);
                }
                ttf_parser::GlyphId(0)
            });
            if let Some(p) = prev {
                pen += f64::from(kern.pair(face, p, gid)) * scale;
            }
            if gid.0 != 0 {
                placed.push((gid, pen));
            }
            pen += f64::from(face.glyph_hor_advance(gid).unwrap_or(0)) * scale;
            prev = Some(gid);
        }
        let x0 = match style.h_align {
            HorizontalAlignment::Left => 0.0,
            HorizontalAlignment::Center => -0.5 * pen,
            HorizontalAlignment::Right => -pen,
        };
        for (gid, x) in placed {
            let mut b = Flattener {
                origin: DVec2::new(x0 + x, baseline),
                scale,
                tolerance,
                contours: &mut out.contours,
                current: Vec::new(),
                last: DVec2::ZERO,
            };
            face.outline_glyph(gid, &mut b);
            b.close();
        }
        out.line_widths.push(pen);
        out.baselines.push(baseline);
    }
    if !missing.is_empty() {
        let list: Vec<String> = missing
            .iter()
            .map(|c| format!("{c:?} (U+{:04X})", u32::from(*c)))
            .collect();
        out.warnings.push(format!(
            "font \"{family}\" has no glyph for {}; left blank (choose a font that has them)",
            list.join(", ")
        ));
    }
    Ok(out)
}

/// Collects a glyph's contours in mm, curves split into chords.
struct Flattener<'a> {
    origin: DVec2,
    scale: f64,
    tolerance: f64,
    contours: &'a mut Vec<Vec<DVec2>>,
    current: Vec<DVec2>,
    last: DVec2,
}

impl Flattener<'_> {
    fn at(&self, x: f32, y: f32) -> DVec2 {
        self.origin + DVec2::new(f64::from(x), f64::from(y)) * self.scale
    }

    fn push(&mut self, p: DVec2) {
        self.current.push(p);
        self.last = p;
    }

    /// Wang's formula: `n = ⌈√(d(d−1)/8 · L / tol)⌉` chords keep a degree-d
    /// Bézier within `tol`, L the largest second difference of its control
    /// points.
    fn chords(&self, factor: f64, l: f64) -> usize {
        ((factor * l / self.tolerance).sqrt().ceil() as usize).clamp(1, 256)
    }
}

impl ttf_parser::OutlineBuilder for Flattener<'_> {
    fn move_to(&mut self, x: f32, y: f32) {
        self.close();
        let p = self.at(x, y);
        self.push(p);
    }

    fn line_to(&mut self, x: f32, y: f32) {
        let p = self.at(x, y);
        self.push(p);
    }

    fn quad_to(&mut self, x1: f32, y1: f32, x: f32, y: f32) {
        let (p0, p1, p2) = (self.last, self.at(x1, y1), self.at(x, y));
        let n = self.chords(0.25, (p0 - 2.0 * p1 + p2).length());
        for k in 1..=n {
            let t = k as f64 / n as f64;
            let u = 1.0 - t;
            self.push(p0 * (u * u) + p1 * (2.0 * u * t) + p2 * (t * t));
        }
    }

    fn curve_to(&mut self, x1: f32, y1: f32, x2: f32, y2: f32, x: f32, y: f32) {
        let (p0, p1, p2, p3) = (self.last, self.at(x1, y1), self.at(x2, y2), self.at(x, y));
        let l = (p0 - 2.0 * p1 + p2)
            .length()
            .max((p1 - 2.0 * p2 + p3).length());
        let n = self.chords(0.75, l);
        for k in 1..=n {
            let t = k as f64 / n as f64;
            let u = 1.0 - t;
            self.push(
                p0 * (u * u * u)
                    + p1 * (3.0 * u * u * t)
                    + p2 * (3.0 * u * t * t)
                    + p3 * (t * t * t),
            );
        }
    }

    fn close(&mut self) {
        let mut c = std::mem::take(&mut self.current);
        if c.len() > 1 && c.first() == c.last() {
            c.pop();
        }
        if c.len() >= 3 {
            self.contours.push(c);
        }
    }
}
