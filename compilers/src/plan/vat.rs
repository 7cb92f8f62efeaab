//! The vat stack's plan: its estimate line and the size that must resolve
//! thin features (the printer's pixel or layer, set by `--preset`), and the
//! options both front ends read from text (layers or shard, offset, the
//! attribute's range), read here one way.

use std::ops::Range;

use volcad_core::Model;

use super::text::{parse_layers, parse_pair};
use super::{Assessment, Opt};
use crate::job::{ExportError, JobContext, Summary};
use crate::resources::human_bytes;
use crate::shard::Shard;
use crate::vat::{self, Intensity, VatParams};

/// The vat options given as text (`None` or blank: not given).
#[derive(Clone, Copy, Debug, Default)]
pub struct VatText<'a> {
    /// `--layers A..B`.
    pub layers: Option<&'a str>,
    /// `--shard K/N`.
    pub shard: Option<&'a str>,
    /// `--offset X,Y` (mm).
    pub offset: Option<&'a str>,
    /// `--range LO,HI` of the intensity attribute.
    pub range: Option<&'a str>,
}

/// A text option's value, `None` when blank.
fn given(t: Option<&str>) -> Option<&str> {
    t.map(str::trim).filter(|t| !t.is_empty())
}

/// What [`VatText`] says, checked.
#[derive(Clone, Debug, PartialEq)]
pub struct VatChoices {
    /// Layers to write.
    pub layers: Option<Range<usize>>,
    /// The shard to write.
    pub shard: Option<Shard>,
    /// The part moved from the screen's centre (mm).
    pub offset: [f64; 2],
}

impl VatText<'_> {
    /// Parse the layer choice and the offset, and set the range on
    /// `intensity` (refused unless it is an attribute).
    pub fn apply(&self, intensity: &mut Intensity) -> Result<VatChoices, ExportError> {
        let layers = given(self.layers)
            .map(|s| parse_layers("--layers", s))
            .transpose()?;
        let shard = given(self.shard).map(str::parse::<Shard>).transpose()?;
        if let (Some(_), Some(s)) = (&layers, shard) {
            return Err(ExportError::param(
                "--shard",
                format!("{s} and --layers both choose layers; give one of them"),
            ));
        }
        let offset = given(self.offset)
            .map(|o| parse_pair("--offset", o, "10,-5"))
            .transpose()?
            .unwrap_or([0.0, 0.0]);
        if let Some(r) = given(self.range) {
            let [lo, hi] = parse_pair("--range", r, "0,1")?;
            match intensity {
                Intensity::Attribute { range, .. } => *range = Some((lo, hi)),
                _ => {
                    return Err(ExportError::param(
                        "--range",
                        "it maps an attribute's values; give --intensity ATTRIBUTE too",
                    ));
                }
            }
        }
        Ok(VatChoices {
            layers,
            shard,
            offset,
        })
    }
}

pub(super) fn estimate(model: &Model, p: &VatParams) -> Result<Assessment, ExportError> {
    let est = vat::estimate(model, p)?;
    let [nx, ny, nz] = est.stack.grid.dims;
    let [w, h] = p.printer.screen;
    let layers = &est.stack.layers;
    Ok(Assessment {
        text: format!(
            "part {nx} × {ny} px of a {w} × {h} px screen, layers {} to {} included ({} of {nz}), {} vat(s), {} files, about {} on disk, {} memory",
            layers.start,
            layers.end.saturating_sub(1),
            layers.len(),
            est.vats,
            est.files,
            human_bytes(est.disk_bytes),
            human_bytes(est.memory_bytes)
        ),
        disk_bytes: Some(est.disk_bytes),
        verdicts: Vec::new(),
    })
}

/// The voxel's largest side (pixel pitch or layer) decides what it
/// resolves; the printer sets it.
pub(super) fn cell(p: &VatParams) -> (f64, Opt) {
    (p.printer.voxel().max_element(), Opt::Preset)
}

pub(super) fn run(model: &Model, p: &VatParams, ctx: &JobContext) -> Result<Summary, ExportError> {
    vat::export_vat(model, p, ctx)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_options_read_one_way() {
        let mut solid = Intensity::Solid;
        let c = VatText {
            layers: Some(" 2..=4 "),
            offset: Some("3,-2"),
            shard: Some(""),
            ..VatText::default()
        }
        .apply(&mut solid)
        .unwrap();
        assert_eq!(
            (c.layers, c.shard, c.offset),
            (Some(2..5), None, [3.0, -2.0])
        );
        let both = VatText {
            layers: Some("1..3"),
            shard: Some("1/2"),
            ..VatText::default()
        };
        let e = both.apply(&mut solid).unwrap_err().to_string();
        assert!(
            e.contains("--shard: 1/2 and --layers both choose layers"),
            "{e}"
        );
        let ranged = VatText {
            range: Some("0,10"),
            ..VatText::default()
        };
        let e = ranged.apply(&mut solid).unwrap_err().to_string();
        assert!(e.contains("give --intensity ATTRIBUTE too"), "{e}");
        let mut attr = Intensity::Attribute {
            name: "t".into(),
            range: None,
        };
        ranged.apply(&mut attr).unwrap();
        assert_eq!(
            attr,
            Intensity::Attribute {
                name: "t".into(),
                range: Some((0.0, 10.0))
            }
        );
    }
}
