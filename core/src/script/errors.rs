//! Script errors in the script's terms: Rhai's nested call errors
//! flattened to the innermost message and position, "function not found"
//! rewritten with the types a script knows, and quoted input clipped.

use rhai::{Engine, EvalAltResult};

use super::ScriptError;

/// The token of a script stopped by its heap budget.
pub(super) const HEAP_STOP: &str = "heap budget";

/// Flatten Rhai's nested "error in function call" wrappers into the inner
/// message at the innermost known position.
pub(super) fn to_script_error(
    e: &EvalAltResult,
    file: &str,
    engine: &Engine,
    max_heap: u64,
) -> ScriptError {
    let mut cur = e;
    let mut pos = e.position();
    while let EvalAltResult::ErrorInFunctionCall(_, _, inner, p) = cur {
        if !p.is_none() {
            pos = *p;
        }
        cur = inner;
    }
    if !cur.position().is_none() {
        pos = cur.position();
    }
    let message = match cur {
        EvalAltResult::ErrorRuntime(v, _) => v.to_string(),
        EvalAltResult::ErrorTerminated(token, _)
            if token
                .clone()
                .into_immutable_string()
                .is_ok_and(|s| s == HEAP_STOP) =>
        {
            format!(
                "stopped: the script's data grew past {} of memory (a value doubled in a \
                 loop?); the budget is {} (MiB) when set, else a quarter of the memory \
                 available when the script started, small on a machine short of memory",
                crate::heap::human_bytes(max_heap),
                crate::heap::BUDGET_VAR
            )
        }
        EvalAltResult::ErrorTerminated(..) => "stopped: the script was cancelled".into(),
        EvalAltResult::ErrorTooManyOperations(_) => {
            "stopped: the script ran too many operations (an endless loop?)".into()
        }
        EvalAltResult::ErrorFunctionNotFound(sig, _) => not_found(sig, engine),
        EvalAltResult::ErrorMismatchDataType(want, got, _) if got == "f64" && want == "i64" => {
            format!(
                "an integer is needed here (an array index, a count), got a number; {INTEGER_HINT}"
            )
        }
        EvalAltResult::ErrorVariableNotFound(var, _) => match var.strip_prefix("global::") {
            Some(plain) => format!(
                "`{var}`: top-level values are seen inside functions by their plain name; write `{plain}`"
            ),
            None => format!(
                "unknown name `{var}`: assign it first (`{var} = ...`), or pass it to the function as an argument"
            ),
        },
        EvalAltResult::ErrorAssignmentToConstant(var, _) => format!(
            "cannot assign `{var}`: it is a constant, or a top-level value seen from inside a \
             function (functions read top-level values but do not change them: declare a local \
             with `let {var} = ...`, or return the new value)"
        ),
        other => {
            let mut s = other.to_string();
            if let Some(i) = s.rfind(" (line ") {
                s.truncate(i);
            }
            s
        }
    };
    ScriptError {
        file: file.to_owned(),
        line: pos.line(),
        column: pos.position(),
        message: clip(&message, MAX_MESSAGE),
    }
}

/// The longest message kept whole: messages quote the script's tokens and
/// values, which can be megabytes (a 10 MB string literal).
pub(super) const MAX_MESSAGE: usize = 400;

/// At most `max` characters of `text`, saying how many were left out:
/// messages that quote user input (a token, a CSV cell, an option value)
/// must not echo megabytes of it.
pub fn clip(text: &str, max: usize) -> String {
    match text.char_indices().nth(max) {
        None => text.to_owned(),
        Some((cut, _)) => format!(
            "{}… ({} more characters)",
            &text[..cut],
            text[cut..].chars().count()
        ),
    }
}

/// What to write where Python's true division gave a float and Rhai needs
/// an integer.
const INTEGER_HINT: &str = "`/` divides as in Python and gives a number: write `floor_div(a, b)` \
     (Python's `a // b`) or `to_int(x)` where an integer is needed";

/// rhai's "Function not found: Tile (volcad_core::node::Node, Vec3)" in the
/// script's terms: argument types by the names a script knows them by; for
/// a known name, that no form of it takes those arguments; for an unknown
/// name, the nearest known one.
fn not_found(sig: &str, engine: &Engine) -> String {
    let (name, args) = match sig.split_once(" (") {
        Some((n, a)) => (n.trim(), a.strip_suffix(')').unwrap_or(a)),
        None => (sig.trim(), ""),
    };
    let raw: Vec<&str> = args.split(", ").filter(|a| !a.is_empty()).collect();
    let float_arg = raw.iter().any(|a| matches!(a.trim(), "f64" | "f32"));
    let args: Vec<&str> = raw.iter().map(|a| script_type(a)).collect();
    if raw.iter().any(|a| a.ends_with("Unassigned")) {
        return format!(
            "`{name}` is given a name that has no value yet ({}): assign it above this line",
            args.join(", ")
        );
    }
    if matches!(name, ".." | "..=") {
        return format!(
            "a range `a{name}b` takes integers, not ({}): loop over integers and scale, \
             e.g. `for k in 1..6 {{ let x = k * 0.5; }}`; {INTEGER_HINT}",
            args.join(", ")
        );
    }
    // Rhai's standard functions (`range`, `sub_string`) count as known.
    let sigs = engine.gen_fn_signatures(true);
    let mut known: Vec<String> = sigs
        .iter()
        .filter_map(|s| s.split('(').next())
        .map(|n| n.trim().to_owned())
        .filter(|n| !n.contains('$'))
        .collect();
    known.sort();
    known.dedup();
    if known.iter().any(|k| k == name) {
        let hint = if float_arg {
            format!("; {INTEGER_HINT}")
        } else {
            String::new()
        };
        return format!(
            "no form of `{name}` takes ({}): check the number, order and types of its \
             arguments (the README's script table lists each form){hint}",
            args.join(", ")
        );
    }
    // An identifier is not suggested an operator (`m.i(..)` is not `*`), and
    // a method is suggested among those its first argument's type has.
    let is_ident = |n: &str| n.chars().all(|c| c.is_alphanumeric() || c == '_');
    let first = args.first().copied().unwrap_or("");
    let takes_first = |n: &str| {
        sigs.iter().any(|s| {
            s.split_once('(').is_some_and(|(k, rest)| {
                k.trim() == n
                    && rest
                        .split([',', ')'])
                        .next()
                        .is_some_and(|p| p.contains(first))
            })
        })
    };
    let candidates: Vec<&str> = known
        .iter()
        .map(String::as_str)
        .filter(|k| is_ident(k) == is_ident(name))
        .collect();
    let methods: Vec<&str> = candidates
        .iter()
        .copied()
        .filter(|k| !first.is_empty() && takes_first(k))
        .collect();
    let near = crate::material::nearest_name(name, methods.iter().copied())
        .or_else(|| crate::material::nearest_name(name, candidates.iter().copied()));
    match near {
        Some(k) => format!("unknown function `{name}`; did you mean `{k}`?"),
        None => format!("unknown function `{name}`"),
    }
}

/// A Rust type name as rhai prints it, in a script's words.
fn script_type(t: &str) -> &str {
    let t = t.trim();
    if t.contains("ImmutableString") {
        return "string";
    }
    match t.rsplit("::").next().unwrap_or(t) {
        "f64" | "f32" => "number",
        "i64" | "i32" | "usize" => "integer",
        "ImmutableString" | "&str" | "String" | "string" => "string",
        "()" => "nothing",
        "Unassigned" => "a name with no value yet",
        other => other,
    }
}
