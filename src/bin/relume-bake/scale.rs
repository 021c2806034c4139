//! Scale-out on the command line: `run --shard I/N` (or the scheduler's environment) and
//! `merge` (docs/scale-out.md); what they tell people is `relume::bake::report`'s.

use clap::Args;
use relume::bake::report::ShardRequest;
use relume::bake::{shard, Sharding};
use relume::Result;
use std::path::{Path, PathBuf};

/// The shard flags of `run`.
#[derive(Args, Clone, Debug)]
pub struct ShardArgs {
    /// Compute only shard I of N of the next expensive stage (form factors, then an
    /// infinite-bounce transport) and write it to --shard-dir; `merge` assembles them. Without
    /// it, SLURM_ARRAY_TASK_ID/SLURM_ARRAY_TASK_COUNT (Slurm job arrays) or JOB_COMPLETION_INDEX
    /// with --shards (Kubernetes Indexed Jobs) select the shard
    #[arg(long, value_name = "I/N", value_parser = shard::parse_shard, conflicts_with = "no_shard")]
    pub shard: Option<(usize, usize)>,
    /// The number of shards when the index comes from the environment (Kubernetes:
    /// JOB_COMPLETION_INDEX)
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=65536), conflicts_with = "no_shard")]
    pub shards: Option<u32>,
    /// Where shard files go (default: OUT.shards beside the output)
    #[arg(long, value_name = "DIR")]
    pub shard_dir: Option<PathBuf>,
    /// Bake whole even inside a Slurm array job (ignore SLURM_ARRAY_TASK_ID)
    #[arg(long)]
    pub no_shard: bool,
}

impl ShardArgs {
    /// The sharding of this `run`, and a note when the environment chose it.
    pub fn sharding(&self, out: &Path) -> Result<(Sharding, Option<String>)> {
        let request = ShardRequest {
            shard: self.shard,
            shards: self.shards,
            shard_dir: self.shard_dir.clone(),
            no_shard: self.no_shard,
        };
        request.sharding(out, |k| std::env::var(k).ok())
    }
}

/// `relume-bake merge`.
#[derive(Args, Clone, Debug)]
pub struct MergeArgs {
    /// The baked directory to write
    pub output: PathBuf,
    /// Directories holding the shard files (`run --shard` wrote them)
    #[arg(required = true, value_name = "SHARD_DIR")]
    pub shard_dirs: Vec<PathBuf>,
    /// Refuse to start when the estimated peak memory exceeds this (e.g. 512M, 8G)
    #[arg(long, value_name = "SIZE", value_parser = relume::limits::parse_bytes)]
    pub max_memory: Option<u64>,
    /// The stage cache the shards used (default: .relume-cache beside the output)
    #[arg(long, value_name = "DIR")]
    pub cache: Option<PathBuf>,
}
