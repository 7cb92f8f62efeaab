//! The Abaqus/CalculiX `.inp` deck.
//!
//! Layout (flat, no `*PART`/`*ASSEMBLY`; CalculiX 2.20 ignores parts and
//! pyvcad 2.3.4's Part/Assembly output with comma-led data lines hangs
//! it):
//!
//! ```text
//! *HEADING / title line / ** comments
//! *NODE, NSET=NALL            ids 1..N
//! **                          (closes the node block for simple readers)
//! *ELEMENT, TYPE=C3D4, ELSET=E_<name>      one block per material, ids 1..M
//! *ELSET, ELSET=EALL          the material sets, one name a line
//! *NSET, NSET=NBOTTOM / NTOP  nodes within tolerance of min / max z
//! *MATERIAL, NAME=<name> + *ELASTIC E, ν    per material with elements
//!   (+ *DENSITY in t/mm³ for property sets from a `density` field)
//! *SOLID SECTION, ELSET=E_<name>, MATERIAL=<name>
//! [step: *BOUNDARY NBOTTOM 1..3; *STEP *STATIC, NTOP dof 3 prescribed,
//!  *NODE FILE U, *EL FILE S, *NODE PRINT RF totals on NBOTTOM, *END STEP]
//! ```
//!
//! Rules kept: no data line starts with a comma; set data lines hold at most
//! 16 entries (Abaqus' limit); numbers are printed from the f64 values with a
//! fixed rule, so the bytes depend only on the mesh.

use std::io::{self, Write};
use volcad_core::names::underscore_other;

use super::{Element, FeaMesh};

/// One material as written.
#[derive(Clone, Debug)]
pub struct MatOut {
    /// Slot in `Model::materials()`.
    pub slot: u16,
    /// Name as written (sanitised, unique).
    pub name: String,
    /// The table's name (for comments).
    pub original: String,
    /// Young's modulus, MPa.
    pub e: f64,
    /// Poisson ratio as written.
    pub nu: f64,
    /// Density (g/cm³), written as `*DENSITY` in the deck's tonne/mm³.
    pub density: Option<f64>,
}

/// Everything the deck needs besides the mesh.
pub struct Deck<'a> {
    /// The mesh.
    pub mesh: &'a FeaMesh,
    /// Materials that have elements, in model order.
    pub materials: &'a [MatOut],
    /// Heading line.
    pub title: String,
    /// Comment lines (written after `**`).
    pub comments: Vec<String>,
    /// 1-based ids of the bottom nodes.
    pub bottom: &'a [u32],
    /// 1-based ids of the top nodes.
    pub top: &'a [u32],
    /// Prescribed top displacement along z (mm), when a step is wanted.
    pub step: Option<f64>,
}

/// A number for the deck: fixed notation with up to 9 decimals, trailing
/// zeros trimmed (`1.5`, `-0.25`, `2850.0`); never exponent notation, which
/// keeps lines short and readable by any Fortran-style reader.
pub fn num(x: f64) -> String {
    let s = if x.abs() >= 1e-3 || x == 0.0 {
        format!("{x:.9}")
    } else {
        format!("{x:.15}")
    };
    let s = s.trim_end_matches('0');
    let s = if s.ends_with('.') {
        format!("{s}0")
    } else {
        s.to_string()
    };
    if s == "-0.0" { "0.0".into() } else { s }
}

/// A name Abaqus and CalculiX accept: a letter first, then letters, digits
/// and `_`, at most 60 characters (so `E_` + name stays under 80), unique
/// case-insensitively among `taken`.
pub fn sanitize(name: &str, taken: &mut Vec<String>) -> String {
    let mut s = underscore_other(name, |c| c.is_ascii_alphanumeric() || c == '_');
    if !s.starts_with(|c: char| c.is_ascii_alphabetic()) {
        s.insert(0, 'M');
    }
    s.truncate(60);
    let mut out = s.clone();
    let mut n = 2;
    while taken.iter().any(|t| t.eq_ignore_ascii_case(&out)) {
        out = format!("{s}_{n}");
        n += 1;
    }
    taken.push(out.clone());
    out
}

/// Comment and title text in plain ASCII (Fortran-era readers, and the
/// summary notes use `°`, `…`, `³`).
pub fn ascii(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '\n' | '\r' => out.push(' '),
            c if c.is_ascii() => out.push(c),
            '°' => out.push_str(" deg"),
            '…' => out.push_str("..."),
            '³' => out.push('3'),
            '²' => out.push('2'),
            '×' => out.push('x'),
            '−' | '–' => out.push('-'),
            'ν' => out.push_str("nu"),
            _ => out.push('?'),
        }
    }
    out
}

/// Characters of comment text a line: with `** ` the lines stay within
/// CalculiX's 132 columns.
const COMMENT_WIDTH: usize = 120;

/// `text` in lines of at most `width` characters, broken at spaces (a
/// longer word is cut).
fn wrap(text: &str, width: usize) -> Vec<String> {
    let (mut lines, mut line) = (Vec::new(), String::new());
    for word in text.split(' ') {
        let mut word = word;
        while !word.is_empty() || line.is_empty() {
            let sep = usize::from(!line.is_empty());
            if line.len() + sep + word.len() <= width {
                if sep == 1 {
                    line.push(' ');
                }
                line.push_str(word);
                break;
            }
            if line.is_empty() {
                // ASCII by now: any byte is a char boundary.
                line.push_str(&word[..width]);
                word = &word[width..];
            }
            lines.push(std::mem::take(&mut line));
        }
    }
    lines.push(line);
    lines
}

fn id_lines(w: &mut impl Write, ids: impl IntoIterator<Item = String>) -> io::Result<()> {
    let mut line = Vec::with_capacity(16);
    for id in ids {
        line.push(id);
        if line.len() == 16 {
            writeln!(w, "{}", line.join(", "))?;
            line.clear();
        }
    }
    if !line.is_empty() {
        writeln!(w, "{}", line.join(", "))?;
    }
    Ok(())
}

/// Write the deck. Element ids are assigned material by material (model
/// order), in mesh order within a material.
pub fn write(w: &mut impl Write, d: &Deck<'_>) -> io::Result<()> {
    let m = d.mesh;
    let per = m.element.nodes_per_element();
    writeln!(w, "*HEADING")?;
    writeln!(w, "{}", ascii(&d.title))?;
    for c in &d.comments {
        for line in wrap(&ascii(c), COMMENT_WIDTH) {
            writeln!(w, "** {line}")?;
        }
    }
    writeln!(w, "*NODE, NSET=NALL")?;
    for (i, p) in m.nodes.iter().enumerate() {
        writeln!(w, "{}, {}, {}, {}", i + 1, num(p.x), num(p.y), num(p.z))?;
    }
    writeln!(w, "**")?;
    let ty = match m.element {
        Element::C3D8R => "C3D8R",
        Element::C3D4 => "C3D4",
    };
    let mut next = 1u64;
    for mat in d.materials {
        writeln!(w, "*ELEMENT, TYPE={ty}, ELSET=E_{}", mat.name)?;
        for (e, _) in m.mat.iter().enumerate().filter(|(_, s)| **s == mat.slot) {
            let conn = &m.conn[e * per..(e + 1) * per];
            let nodes: Vec<String> = conn.iter().map(|n| (n + 1).to_string()).collect();
            writeln!(w, "{next}, {}", nodes.join(", "))?;
            next += 1;
        }
    }
    // One set name per line: Abaqus allows several, but meshio (and other
    // simple readers) take only the first name of each line.
    writeln!(w, "*ELSET, ELSET=EALL")?;
    for mat in d.materials {
        writeln!(w, "E_{}", mat.name)?;
    }
    for (name, ids) in [("NBOTTOM", d.bottom), ("NTOP", d.top)] {
        if !ids.is_empty() {
            writeln!(w, "*NSET, NSET={name}")?;
            id_lines(w, ids.iter().map(|i| i.to_string()))?;
        }
    }
    for mat in d.materials {
        if mat.original != mat.name {
            writeln!(w, "** material \"{}\" of the table", ascii(&mat.original))?;
        }
        writeln!(w, "*MATERIAL, NAME={}", mat.name)?;
        writeln!(w, "*ELASTIC")?;
        writeln!(w, "{}, {}", num(mat.e), num(mat.nu))?;
        if let Some(rho) = mat.density {
            // mm, N, MPa: mass in tonnes, so 1 g/cm³ = 1e-9 t/mm³.
            writeln!(w, "*DENSITY")?;
            writeln!(w, "{}", num(rho * 1e-9))?;
        }
        writeln!(
            w,
            "*SOLID SECTION, ELSET=E_{}, MATERIAL={}",
            mat.name, mat.name
        )?;
    }
    if let Some(uz) = d.step {
        writeln!(
            w,
            "** ---- static step: bottom clamped, top moved along z ----"
        )?;
        writeln!(w, "*BOUNDARY")?;
        writeln!(w, "NBOTTOM, 1, 3")?;
        writeln!(w, "*STEP")?;
        writeln!(w, "*STATIC")?;
        writeln!(w, "*BOUNDARY")?;
        writeln!(w, "NTOP, 3, 3, {}", num(uz))?;
        writeln!(w, "*NODE FILE")?;
        writeln!(w, "U")?;
        writeln!(w, "*EL FILE")?;
        writeln!(w, "S")?;
        writeln!(w, "*NODE PRINT, NSET=NBOTTOM, TOTALS=ONLY")?;
        writeln!(w, "RF")?;
        writeln!(w, "*END STEP")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_names() {
        assert_eq!(num(1.5), "1.5");
        assert_eq!(num(-0.25), "-0.25");
        assert_eq!(num(2850.0), "2850.0");
        assert_eq!(num(0.0), "0.0");
        assert_eq!(num(-0.0), "0.0");
        assert_eq!(num(1e-300), "0.0");
        assert_eq!(num(2.5e-5), "0.000025");
        assert_eq!(num(1.0 / 3.0), "0.333333333");
        let mut taken = Vec::new();
        assert_eq!(sanitize("VeroCyan", &mut taken), "VeroCyan");
        assert_eq!(sanitize("gray 128", &mut taken), "gray_128");
        assert_eq!(sanitize("Gray_128", &mut taken), "Gray_128_2");
        assert_eq!(sanitize("3d-red", &mut taken), "M3d_red");
        assert_eq!(wrap("aa bb cc", 5), vec!["aa bb", "cc"]);
        assert_eq!(wrap("abcdefg h", 3), vec!["abc", "def", "g h"]);
        assert_eq!(
            ascii("10° … 165°, 1 mm³ ×2\n"),
            "10 deg ... 165 deg, 1 mm3 x2 "
        );
    }
}
