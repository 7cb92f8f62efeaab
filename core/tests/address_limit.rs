//! Under an address-space limit (`ulimit -v`), a script that doubles a
//! string stops at its heap budget instead of aborting the process on a
//! failed allocation. The only test of its binary: the limit it sets holds
//! for the whole process.

// A test crate: its helper functions stop on a failed setup as its tests do.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use rustix::process::{Resource, getrlimit, setrlimit};
use volcad_core::heap::{CountingAllocator, address_space_left};
use volcad_core::script::{ScriptOptions, run_script};

#[global_allocator]
static HEAP: CountingAllocator = CountingAllocator;

/// The process's virtual size now (`VmSize`), in bytes.
fn vm_size() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("status");
    let line = status
        .lines()
        .find(|l| l.starts_with("VmSize:"))
        .expect("VmSize");
    let kib: u64 = line
        .split_whitespace()
        .nth(1)
        .expect("kB")
        .parse()
        .expect("number");
    kib * 1024
}

#[test]
fn a_doubling_string_under_ulimit_v_meets_the_script_budget() {
    let old = getrlimit(Resource::As);
    let mut limit = old;
    limit.current = Some(vm_size() + (1 << 30));
    setrlimit(Resource::As, limit).expect("lower the address-space limit");
    let left = address_space_left().expect("a limit is set");
    assert!(left <= 1 << 30, "{left}");

    let src = "let m = default_materials();\nlet s = \"ab\";\nfor i in 0..60 { s += s; }\nSphere(Vec3(0,0,0), 1, m.id(\"red\"))";
    let opts = ScriptOptions::default();
    assert!(
        opts.max_heap <= left / 4,
        "budget {} of {left}",
        opts.max_heap
    );
    let e = run_script(src, "double.rhai", &opts).expect_err("stops");
    assert!(e.message.contains("grew past"), "{e}");
    assert_eq!(e.line, Some(3), "{e}");
    setrlimit(Resource::As, old).expect("restore");
}
