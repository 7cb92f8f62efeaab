//! The end-to-end tests of Volcad Studio: the whole pipeline driven the way a
//! user drives it.
//!
//! - `tests/tests/cli*.rs`, `shard.rs`: the `volcad` command line as a
//!   process (exports, refusals, shards and the deploy scripts), helpers in
//!   `tests/tests/cli_common/`.
//! - `tests/tests/studio_*.rs`: the studio in an egui kittest harness drawn
//!   by wgpu (lavapipe where there is no GPU), helpers in `tests/tests/common/`.
//! - `tests/tests/smoke.rs`: the real `volcad-studio` binary in Xvfb.
//! - `tests/tests/fuzz.rs`: the fuzzing corpus replayed, and a bounded
//!   generated run ([`fuzz`]; `cargo run -p volcad-tests --bin fuzz` runs
//!   it for longer).
//!
//! This library holds what those tests share: [`bins`] finds the binaries
//! they run, [`fuzz`] generates and classifies fuzz cases.

pub mod bins;
pub mod fuzz;

pub use bins::bin;
