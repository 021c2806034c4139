//! What `relume-bake run`, `merge` and the stage subcommands tell people: where a bake went,
//! which stages were reused, which shard was written; and the default places beside an output
//! (the stage cache, the shard directory) with the sharding a `run` is asked for.

use crate::bake::shard::{self, Sharding};
use crate::bake::BakeReport;
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// `.relume-cache` in the output's parent directory (the working directory when it has none).
pub fn default_cache(out: &Path) -> PathBuf {
    match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.join(".relume-cache"),
        _ => PathBuf::from(".relume-cache"),
    }
}

/// `OUT.shards` beside the output.
pub fn default_shard_dir(out: &Path) -> PathBuf {
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "bake".into());
    out.with_file_name(format!("{name}.shards"))
}

/// The shard a `run` is asked for: `shard` (I, N) given, `shards` N for an index from the
/// environment, where shard files go (default [`default_shard_dir`]), or `no_shard`.
#[derive(Clone, Debug, Default)]
pub struct ShardRequest {
    pub shard: Option<(usize, usize)>,
    pub shards: Option<u32>,
    pub shard_dir: Option<PathBuf>,
    pub no_shard: bool,
}

impl ShardRequest {
    /// The sharding of a `run` writing `out`, and a note when the environment chose it; `env`
    /// reads an environment variable (Slurm job arrays, Kubernetes Indexed Jobs).
    pub fn sharding(
        &self,
        out: &Path,
        env: impl Fn(&str) -> Option<String>,
    ) -> Result<(Sharding, Option<String>)> {
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

/// What `run` tells people: where the bake went, and which stages were reused or skipped.
pub fn bake_summary(report: &BakeReport) -> String {
    let bytes: u64 = report.files.iter().map(|f| f.bytes).sum();
    let size = crate::limits::human_bytes(bytes);
    if report.up_to_date {
        return format!(
            "up to date: {} already holds this bake ({} files, {size}, all verified); nothing to do\n",
            report.output.display(),
            report.files.len() + 1
        );
    }
    let mut s = format!(
        "baked {} ({} files, {size})\n",
        report.output.display(),
        report.files.len() + 1
    );
    let cached: Vec<&str> = report
        .stages
        .iter()
        .filter(|t| t.cached)
        .map(|t| t.stage.as_str())
        .collect();
    if !cached.is_empty() {
        let ran: Vec<&str> = report
            .stages
            .iter()
            .filter(|t| !t.cached && t.stage != "load")
            .map(|t| t.stage.as_str())
            .collect();
        s += &format!(
            "reused from the stage cache: {}; ran: {}\n",
            cached.join(", "),
            if ran.is_empty() {
                "nothing".to_string()
            } else {
                ran.join(", ")
            }
        );
    }
    s
}

/// What a sharded `run` or a `merge` writing `out` tells people, or `None` for a whole bake.
pub fn shard_summary(report: &BakeReport, out: &Path) -> Option<String> {
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

/// What a sharded `run` that found every shardable stage in the cache tells people.
pub fn nothing_to_shard(out: &Path) -> String {
    format!(
        "nothing to shard: every expensive stage of this bake is in the stage cache; run `relume-bake merge {} SHARD_DIR` to finish it\n",
        out.display()
    )
}

/// What a stage run alone on the bake in `dir` did: one line per stage with its time and
/// outputs, then its measurements indented.
pub fn stage_lines(report: &BakeReport, dir: &Path) -> String {
    let mut s = String::new();
    for t in &report.stages {
        s += &format!(
            "ran {} on {} in {:.2} s → {}\n",
            t.stage,
            dir.display(),
            t.seconds,
            t.outputs.join(", ")
        );
        for (k, v) in &t.report {
            s += &format!("  {k:<28} {v}\n");
        }
    }
    s
}
