//! The language reference: every script function a design can call, its
//! forms with argument names and types, a one-line description and an
//! example; and the math strings' variables, operators and functions.
//!
//! The studio's Help window, its hover tooltips and its completion read
//! this table. It cannot drift from the engine: a test lists every
//! function the engine registers and fails for one without an entry (and
//! for an entry the engine does not have), and runs every example.

/// What kind of thing a reference entry is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Group {
    /// A solid: distance and a material.
    Geometry,
    /// Lattices and periodic structures.
    Lattice,
    /// Combining children.
    Boolean,
    /// Moving, scaling, offsetting a child.
    Transform,
    /// Materials and grading.
    Material,
    /// Files beside the design.
    Data,
    /// A method called on a node (`node.add_child(x)`).
    Method,
    /// Vectors, parameters and other values.
    Value,
}

impl Group {
    /// The heading in the reference.
    pub fn title(self) -> &'static str {
        match self {
            Group::Geometry => "Geometry",
            Group::Lattice => "Lattices",
            Group::Boolean => "Booleans",
            Group::Transform => "Transforms",
            Group::Material => "Materials",
            Group::Data => "Data",
            Group::Method => "Node methods",
            Group::Value => "Values",
        }
    }
}

/// One script function.
#[derive(Clone, Copy, Debug)]
pub struct FnDoc {
    /// The name a script calls.
    pub name: &'static str,
    /// Its group.
    pub group: Group,
    /// Every form, with argument names and types.
    pub forms: &'static [&'static str],
    /// One line on what it does.
    pub summary: &'static str,
    /// What completion inserts.
    pub skeleton: &'static str,
    /// A complete script that uses it (the test runs it).
    pub example: &'static str,
}

/// One name a math string may use.
#[derive(Clone, Copy, Debug)]
pub struct MathDoc {
    /// The variable, operator or function.
    pub name: &'static str,
    /// What it is.
    pub summary: &'static str,
}

mod functions;
mod math;

pub use functions::FUNCTIONS;
pub use math::MATH;

/// The entry for `name`, if it is a script function.
pub fn lookup(name: &str) -> Option<&'static FnDoc> {
    FUNCTIONS.iter().find(|f| f.name == name)
}

/// Entries whose name or summary contains `query` (case-insensitive).
pub fn search(query: &str) -> impl Iterator<Item = &'static FnDoc> {
    let q = query.to_lowercase();
    FUNCTIONS.iter().filter(move |f| {
        q.is_empty() || f.name.to_lowercase().contains(&q) || f.summary.to_lowercase().contains(&q)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::script::{ScriptOptions, registered_functions, run_script};

    /// Rhai's own functions (operators, string and array methods) are not
    /// ours to document.
    fn ours(name: &str) -> bool {
        !matches!(
            name,
            "to_string" | "to_debug" | "+" | "-" | "*" | "/" | "%" | "**" | "/=" | "%=" | "**="
                | "==" | "!=" | "x" | "y" | "z"
                // Rhai's own math and `range`, given Python's integer forms.
                | "sqrt" | "exp" | "ln" | "log" | "sin" | "cos" | "tan" | "asin" | "acos"
                | "atan" | "sinh" | "cosh" | "tanh" | "range"
        ) && !name.starts_with("get$")
            && !name.starts_with("set$")
    }

    #[test]
    fn every_registered_function_has_an_entry_and_no_entry_is_stale() {
        let names = registered_functions();
        let missing: Vec<_> = names
            .iter()
            .filter(|n| ours(n) && lookup(n).is_none())
            .collect();
        assert!(
            missing.is_empty(),
            "functions without a reference entry: {missing:?}"
        );
        let stale: Vec<_> = FUNCTIONS
            .iter()
            .filter(|f| !names.iter().any(|n| n == f.name))
            .map(|f| f.name)
            .collect();
        assert!(
            stale.is_empty(),
            "entries the engine does not have: {stale:?}"
        );
    }

    #[test]
    fn every_example_runs() {
        for f in FUNCTIONS.iter().filter(|f| !f.example.is_empty()) {
            if let Err(e) = run_script(f.example, "example.rhai", &ScriptOptions::default()) {
                panic!("{}'s example fails: {e}", f.name);
            }
        }
    }

    #[test]
    fn search_finds_by_name_and_summary() {
        assert!(search("sphere").any(|f| f.name == "Sphere"));
        assert!(search("rounds the joins").any(|f| f.name == "Union"));
        assert_eq!(search("").count(), FUNCTIONS.len());
    }
}
