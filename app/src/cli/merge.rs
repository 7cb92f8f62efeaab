//! `volcad merge OUT SHARD_DIR...`: join the folders of a sharded layer
//! stack (`volcad export png ... --shard K/N`) into the folder the export
//! without `--shard` writes, byte for byte. Every check (same design,
//! parameters and seed; layers tiling the grid; files present) runs before
//! anything is written, and OUT is staged and renamed like an export's
//! folder (compilers/src/job.rs), so a refused or interrupted merge leaves
//! nothing behind. The logic is `volcad_compilers::shard`.

use std::path::PathBuf;

use volcad_compilers::job;
use volcad_compilers::resources::check_disk_for;
use volcad_compilers::shard::plan_merge;

use super::export::{follow, interrupt_flag};

/// `volcad merge` arguments.
#[derive(clap::Args, Debug)]
pub struct MergeArgs {
    /// Output folder: the combined export, as `volcad export png` without
    /// `--shard` writes it (staged, renamed when complete).
    pub out: PathBuf,
    /// The shard folders, in any order (each the `--out` of one
    /// `volcad export png ... --shard K/N`).
    #[arg(required = true, value_name = "SHARD_DIR")]
    pub shards: Vec<PathBuf>,
}

/// Run `volcad merge`.
pub fn merge(a: &MergeArgs) -> anyhow::Result<()> {
    let plan = plan_merge(&a.shards)?;
    plan.check_destination(&a.out)?;
    check_disk_for(plan.bytes, &a.out, "another disk")?;
    note!(
        "{} shard folder(s), {} files, {:.1} MB to copy",
        plan.shards,
        plan.summary.files.len(),
        plan.bytes as f64 / 1e6
    );
    let interrupted = interrupt_flag();
    let hash = plan.design_hash.clone();
    let handle = job::spawn(a.out.clone(), hash, move |ctx| plan.run(ctx));
    follow(handle, &interrupted)
}
