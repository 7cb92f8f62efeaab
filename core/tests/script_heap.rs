//! A script that allocates without bound stops with an error, and the
//! process goes on (this test binary installs the counting allocator, as
//! the `volcad` and `volcad-studio` binaries do).

// A test crate: its helper functions stop on a failed setup as its tests do.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use volcad_core::heap::{CountingAllocator, live_bytes};
use volcad_core::script::{ScriptOptions, run_script};

#[global_allocator]
static HEAP: CountingAllocator = CountingAllocator;

fn opts(max_heap_mib: u64) -> ScriptOptions {
    ScriptOptions {
        max_heap: max_heap_mib << 20,
        ..ScriptOptions::default()
    }
}

#[test]
fn doubling_loops_stop_with_an_error_that_says_where() {
    assert!(
        live_bytes().is_some(),
        "the counting allocator is installed"
    );
    for (what, body) in [
        ("string", "let s = \"ab\";\nfor i in 0..60 { s += s; }"),
        ("array", "let a = [1, 2];\nfor i in 0..60 { a += a; }"),
    ] {
        let src =
            format!("let m = default_materials();\n{body}\nSphere(Vec3(0,0,0), 1, m.id(\"red\"))");
        let e = run_script(&src, "runaway.rhai", &opts(64)).expect_err(what);
        assert!(
            e.message.contains("grew past 64 MiB of memory"),
            "{what}: {e}"
        );
        assert_eq!(e.line, Some(3), "{what}: {e}");
    }
    // The process is fine, and a script within its budget runs.
    let ok = "let m = default_materials();\nlet a = [];\nfor i in 0..20000 { a.push(i); }\nSphere(Vec3(0,0,0), a.len() / 10000.0, m.id(\"red\"))";
    assert!(run_script(ok, "ok.rhai", &opts(64)).is_ok());
}
