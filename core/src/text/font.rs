//! Fonts by family name: the machine's fonts through fontdb (the folders
//! fontconfig lists), and DejaVu Sans built into the binary, so a design
//! with text builds on a bare machine and the tests do not depend on what
//! is installed.

use std::sync::OnceLock;

use super::FontAspect;

/// DejaVu Sans 2.37 (Bitstream Vera licence, `assets/fonts/`), the family
/// pyvcad falls back to on Linux.
pub(super) static BUNDLED: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

/// The bundled font's family name.
pub const BUNDLED_FAMILY: &str = "DejaVu Sans";

/// The machine's fonts, scanned once per process (the scan reads every
/// font file's name table).
fn system() -> &'static fontdb::Database {
    static DB: OnceLock<fontdb::Database> = OnceLock::new();
    DB.get_or_init(|| {
        let mut db = fontdb::Database::new();
        db.load_system_fonts();
        db
    })
}

fn weight_style(aspect: FontAspect) -> (fontdb::Weight, fontdb::Style) {
    match aspect {
        FontAspect::Regular => (fontdb::Weight::NORMAL, fontdb::Style::Normal),
        FontAspect::Bold => (fontdb::Weight::BOLD, fontdb::Style::Normal),
        FontAspect::Italic => (fontdb::Weight::NORMAL, fontdb::Style::Italic),
        FontAspect::BoldItalic => (fontdb::Weight::BOLD, fontdb::Style::Italic),
    }
}

/// The machine's face of `family` (any letter case) nearest to `aspect`,
/// and whether it is that aspect.
fn system_face(family: &str, aspect: FontAspect) -> Option<(fontdb::ID, bool)> {
    let db = system();
    let wanted = family.trim().to_lowercase();
    let name = db.faces().find_map(|f| {
        f.families
            .iter()
            .find(|(n, _)| n.to_lowercase() == wanted)
            .map(|(n, _)| n.clone())
    })?;
    let (weight, style) = weight_style(aspect);
    let id = db.query(&fontdb::Query {
        families: &[fontdb::Family::Name(&name)],
        weight,
        stretch: fontdb::Stretch::Normal,
        style,
    })?;
    let face = db.face(id)?;
    let bold = face.weight.0 >= 600;
    let slanted = face.style != fontdb::Style::Normal;
    let exact = bold == (weight.0 >= 600) && slanted == (style != fontdb::Style::Normal);
    Some((id, exact))
}

/// Run `f` on the font for `family` and `aspect`, with the family name it
/// used. Order: the bundled font for its own family in the regular
/// aspect (the same outlines on every machine); else the machine's face;
/// else, with a warning that names the family asked for, DejaVu Sans: the
/// built-in face for `Regular`, the machine's face for another aspect if
/// it has one. `Err` only when the font data cannot be parsed.
pub fn with_font<T>(
    family: &str,
    aspect: FontAspect,
    warnings: &mut Vec<String>,
    f: impl FnOnce(&ttf_parser::Face<'_>, &str) -> T,
) -> Result<T, String> {
    let is_bundled = family.trim().eq_ignore_ascii_case(BUNDLED_FAMILY);
    if is_bundled && aspect == FontAspect::Regular {
        return bundled(f);
    }
    let found = system_face(family, aspect);
    let (id, used) = match found {
        Some((id, exact)) => {
            if !exact {
                warnings.push(format!(
                    "font \"{family}\" has no {} face on this machine; its nearest face is used",
                    aspect.name()
                ));
            }
            (Some(id), family.trim().to_owned())
        }
        None => {
            if !is_bundled {
                warnings.push(format!(
                    "font family \"{family}\" is not installed on this machine; using \
                     {BUNDLED_FAMILY} (give an installed family, or install the font)"
                ));
            }
            let styled = (aspect != FontAspect::Regular)
                .then(|| system_face(BUNDLED_FAMILY, aspect))
                .flatten();
            match styled.filter(|(_, exact)| *exact) {
                Some((id, _)) => (Some(id), BUNDLED_FAMILY.to_owned()),
                None => {
                    if aspect != FontAspect::Regular {
                        warnings.push(format!(
                            "the built-in {BUNDLED_FAMILY} has only its regular face; \
                             FontAspect::{} is drawn regular",
                            aspect.name()
                        ));
                    }
                    (None, BUNDLED_FAMILY.to_owned())
                }
            }
        }
    };
    let Some(id) = id else {
        return bundled(f);
    };
    let out = system().with_face_data(id, |data, index| {
        ttf_parser::Face::parse(data, index)
            .map(|face| f(&face, &used))
            .map_err(|e| format!("font \"{used}\" cannot be read: {e}"))
    });
    out.unwrap_or_else(|| Err(format!("font \"{used}\" cannot be read from its file")))
}

fn bundled<T>(f: impl FnOnce(&ttf_parser::Face<'_>, &str) -> T) -> Result<T, String> {
    ttf_parser::Face::parse(BUNDLED, 0)
        .map(|face| f(&face, BUNDLED_FAMILY))
        .map_err(|e| format!("the built-in font cannot be read: {e}"))
}
