//! Legacy OpenVCAD `.vcad` text designs (pyvcad 2.3.4's
//! `parse_vcad_text`), read into the same
//! [`Design`] a Rhai script builds.
//!
//! The text is lexed (`lexer`), parsed into calls (`parser`) and
//! translated straight into the node tree (`translate`), not into Rhai
//! source: every message then comes from code that holds the `.vcad`
//! line and column itself (an unknown construct, a wrong argument, an
//! error inside an expression string, and, through each node's origin, a
//! problem found at prepare), with no second set of positions to map back.
//! Materials are named from pyvcad's default table, as `default_materials()`
//! gives a script; files (`mesh`) resolve beside the design as a script's do.

mod lexer;
mod parser;
#[cfg(test)]
mod tests;
mod translate;

use std::path::Path;
use std::sync::Arc;

use crate::material::MaterialTable;
use crate::script::{Design, RunContext, ScriptError, ScriptOptions};

/// A problem at a line and column of the `.vcad` text.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct VcadError {
    line: usize,
    column: usize,
    message: String,
}

impl VcadError {
    pub(crate) fn at(line: usize, column: usize, message: String) -> Self {
        Self {
            line,
            column,
            message,
        }
    }
}

/// Whether `name` (a path or file name) is a `.vcad` design.
pub(crate) fn is_vcad(name: impl AsRef<Path>) -> bool {
    name.as_ref()
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("vcad"))
}

/// Read a `.vcad` design: `name` is the file name errors carry; `opts`
/// gives the folder `mesh("...")` paths resolve in (parameters do not
/// apply: the language has none).
pub(crate) fn run_vcad(
    source: &str,
    name: &str,
    opts: &ScriptOptions,
) -> Result<Design, ScriptError> {
    let to_err = |e: VcadError| ScriptError {
        file: name.to_owned(),
        line: Some(e.line),
        column: Some(e.column),
        message: e.message,
    };
    let toks = lexer::tokenize(source).map_err(to_err)?;
    let call = parser::parse(&toks, end_of(source)).map_err(to_err)?;
    let table = Arc::new(MaterialTable::default_table());
    // Files resolve as a script's do (`.vcad` has no parameters).
    let files = opts
        .base_dir
        .is_some()
        .then(|| RunContext::from_options(opts));
    let mut t = translate::Translator {
        table: &table,
        files,
        warnings: Vec::new(),
    };
    let root = t.root(&call).map_err(to_err)?;
    let warnings = t.warnings;
    Ok(Design {
        root,
        materials: table,
        params: Vec::new(),
        log: Vec::new(),
        warnings,
    })
}

/// Run a design text as `.vcad` or Rhai by its file name's extension.
pub fn run_design(source: &str, name: &str, opts: &ScriptOptions) -> Result<Design, ScriptError> {
    if is_vcad(name) {
        run_vcad(source, name, opts)
    } else {
        crate::script::run_script(source, name, opts)
    }
}

/// The line and column just past the last character (where "the end of the
/// file" errors point).
fn end_of(source: &str) -> parser::Pos {
    let line = source.lines().count().max(1) + usize::from(source.ends_with('\n'));
    let column = if source.ends_with('\n') {
        1
    } else {
        source.lines().last().map_or(0, |l| l.chars().count()) + 1
    };
    parser::Pos { line, column }
}
