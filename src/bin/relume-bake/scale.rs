//! Scale-out on the command line: `run --shard I/N` (or the scheduler's environment), `merge`,
//! and what they tell people (docs/scale-out.md).

use clap::Args;
use relume::bake::{shard, BakeReport, Sharding};
use relume::error::Error;
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

/// `OUT.shards` beside the output.
pub fn default_shard_dir(out: &Path) -> PathBuf {
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "bake".into());
    out.with_file_name(format!("{name}.shards"))
}

impl ShardArgs {
    /// The sharding of this `run`, and a note when the environment chose it.
    pub fn sharding(&self, out: &Path) -> Result<(Sharding, Option<String>)> {
        let dir = self
            .shard_dir
            .clone()
            .unwrap_or_else(|| default_shard_dir(out));
        if self.no_shard {
            return Ok((Sharding::Whole, None));
        }
        if let Some((index, count)) = self.shard {
            return Ok((Sharding::Shard { index, count, dir }, None));
        }
        let env = |k: &str| std::env::var(k).ok();
        match shard::shard_from_env(self.shards.map(|n| n as usize), env).map_err(Error::knob)? {
            Some((index, count, source)) => Ok((
                Sharding::Shard { index, count, dir },
                Some(format!(
                    "shard {index}/{count} from {source} (--no-shard bakes the whole pipeline)"
                )),
            )),
            None => Ok((Sharding::Whole, None)),
        }
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

/// What a sharded `run` or a `merge` tells people, or `None` for a whole bake.
pub fn summary(report: &BakeReport, out: &Path) -> Option<String> {
    if let Some(s) = &report.shard {
        return Some(format!(
            "{} shard {}/{} of `{}` ({}): {}\n",
            if s.reused {
                "already there, verified:"
            } else {
                "wrote"
            },
            s.index,
            s.count,
            s.stage,
            s.part,
            s.path.display()
        ));
    }
    if let Some(stage) = &report.needs_shards {
        let merged: Vec<&str> = report
            .stages
            .iter()
            .filter(|t| t.stage != "load")
            .map(|t| t.stage.as_str())
            .collect();
        return Some(format!(
            "merged up to `{}`, kept in the stage cache; `{stage}` needs its shards next: run \
             `relume-bake run PIPELINE --out {} --shard I/N` for every I, then merge again\n",
            merged.last().copied().unwrap_or("load"),
            out.display()
        ));
    }
    None
}

/// A sharded `run` that found every shardable stage in the cache.
pub fn nothing_to_shard(out: &Path) -> String {
    format!(
        "nothing to shard: every expensive stage of this bake is in the stage cache; run `relume-bake merge {} SHARD_DIR` to finish it\n",
        out.display()
    )
}
