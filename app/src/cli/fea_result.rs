//! `volcad fea-result`: a CalculiX result as CSV.

use std::path::Path;

/// `volcad fea-result JOB.frd --inp JOB.inp --out result.csv` (`--out -`
/// for standard output). The CSV is made in memory first: a deck that does
/// not match the result leaves no file.
pub fn fea_result(frd: &Path, inp: &Path, out: &Path) -> anyhow::Result<()> {
    super::output::check_regular(frd, "CalculiX result (.frd)")?;
    super::output::check_regular(inp, "deck (.inp)")?;
    super::output::target(out, "--out")?;
    let r = volcad_compilers::fea::read_frd(frd)?;
    let (text, _) = volcad_compilers::fea::result_csv(&r, Some(inp))?;
    super::output::write_output(out, "--out", |w| w.write_all(text.as_bytes()))?;
    note!("{} nodes -> {}", r.displacements.len(), out.display());
    Ok(())
}
