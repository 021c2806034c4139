//! Bakes split over processes (docs/scale-out.md): `run --shard I/N` computes part I of the first
//! expensive stage the stage cache does not hold and writes it as a shard file; `merge` checks a
//! complete set of shards, assembles the stage as a single process would have made it, keeps it
//! in the stage cache, and goes on — to the end of the pipeline, or to the next stage that needs
//! shards (a second round).
//!
//! Shardable stages: `form_factors` (rows) and `transport` with `bounces: Infinite` (panels of
//! columns). Everything else runs in each shard (cheap stages before, taken from the cache when
//! there) or in the merge (cheap stages after).

use super::stages::StageRun;
use super::workspace::Workspace;
use crate::baked::manifest::{hash_file, sha256_hex};
use crate::baked::shard::{self, Mapped, Payload, ShardHeader};
use crate::error::{Error, Result};
use crate::pipeline::Pipeline;
use crate::progress::Progress;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// How a bake is split.
#[derive(Clone, Debug, Default)]
pub enum Sharding {
    /// One process bakes everything.
    #[default]
    Whole,
    /// Compute part `index` of `count` of the next shardable stage into `dir`.
    Shard {
        index: usize,
        count: usize,
        dir: PathBuf,
    },
    /// Assemble shardable stages from the shards in `dirs`.
    Merge { dirs: Vec<PathBuf> },
}

/// What a shard process wrote.
#[derive(Clone, Debug, Serialize)]
pub struct ShardWritten {
    pub stage: String,
    pub index: usize,
    pub count: usize,
    pub part: String,
    pub path: PathBuf,
    /// The file was already there, made from the same inputs, and verified: nothing was computed.
    pub reused: bool,
}

/// The header of the shard at `path` when it exists, belongs to bake `bake`, has stage key
/// `key` and verifies whole (payload hash); `None` otherwise.
pub fn intact(path: &Path, bake: &str, key: &str) -> Option<ShardHeader> {
    let h = shard::read_header(path).ok()?;
    if h.bake != bake || h.key != key {
        return None;
    }
    shard::read(path).ok().map(|(h, _)| h)
}

/// Where one shard of a stage goes, and what it is made from.
pub struct ShardAt<'a> {
    pub pipeline: &'a Pipeline,
    pub stage: &'a str,
    /// The stage's cache key.
    pub key: &'a str,
    pub index: usize,
    pub count: usize,
    pub dir: &'a Path,
}

impl ShardAt<'_> {
    /// Compute the shard with `run` and write it — or, when an intact shard made from the same
    /// inputs is already there (a retried or resubmitted task), keep it.
    pub fn compute(
        &self,
        run: &dyn StageRun,
        ws: &mut Workspace,
        progress: &dyn Progress,
    ) -> Result<ShardWritten> {
        let bake = bake_id(self.pipeline)?;
        let path = self.dir.join(shard::file_name(
            self.stage,
            self.index as u32,
            self.count as u32,
        ));
        let written = |part: String, path: PathBuf, reused: bool| ShardWritten {
            stage: self.stage.into(),
            index: self.index,
            count: self.count,
            part,
            path,
            reused,
        };
        if let Some(h) = intact(&path, &bake, self.key) {
            return Ok(written(h.part, path, true));
        }
        let prepared = read_prepared(self.dir, self.stage, self.key, &bake)?;
        let (part, payload) = run.run_shard(ws, self.index, self.count, prepared, progress)?;
        let header = ShardHeader::new(
            bake,
            self.stage.into(),
            (self.index, self.count),
            self.key,
            self.pipeline,
            part.clone(),
        );
        let path = shard::write(self.dir, header, &payload)?;
        Ok(written(part, path, false))
    }
}

/// The stage name under which the work done once before a stage's shards is stored
/// (`transport-prepared.0-of-1.shard`: the LU factors).
pub fn prepared_name(stage: &str) -> String {
    format!("{stage}-prepared")
}

/// The prepared arrays of `stage` in `dir`, verified whole and checked to be of this bake and
/// stage key; `None` when there is no such file.
pub fn read_prepared(dir: &Path, stage: &str, key: &str, bake: &str) -> Result<Option<Mapped>> {
    let path = dir.join(shard::file_name(&prepared_name(stage), 0, 1));
    if !path.exists() {
        return Ok(None);
    }
    let mapped = Mapped::open(&path)?;
    let h = &mapped.header;
    if h.bake != bake || h.key != key {
        return Err(Error::verify(
            &path,
            format!("made for another bake or other inputs of `{stage}`: run the merge of the previous round again"),
        ));
    }
    Ok(Some(mapped))
}

/// Store what `stage`'s shards need, made once by the merge of the previous round.
pub fn write_prepared(
    dir: &Path,
    pipeline: &Pipeline,
    stage: &str,
    key: &str,
    payload: &Payload,
) -> Result<PathBuf> {
    let header = ShardHeader::new(
        bake_id(pipeline)?,
        prepared_name(stage),
        (0, 1),
        key,
        pipeline,
        format!("prepared once for the shards of `{stage}`"),
    );
    shard::write(dir, header, payload)
}

/// Which bake shards belong to: the pipeline and the input file's content.
pub fn bake_id(pipeline: &Pipeline) -> Result<String> {
    let (_, input) = hash_file(pipeline.input.path())?;
    let text = serde_json::to_string(pipeline).map_err(|e| Error::Internal(e.to_string()))?;
    Ok(sha256_hex(format!("{text}\n{input}").as_bytes()))
}

/// Every shard header in `dirs`, checked to belong to one bake.
pub struct ShardSet {
    pub headers: Vec<(PathBuf, ShardHeader)>,
}

impl ShardSet {
    /// Read the headers of every `*.shard` file in `dirs` (not recursive).
    pub fn scan(dirs: &[PathBuf]) -> Result<Self> {
        let mut headers = Vec::new();
        for d in dirs {
            let entries = std::fs::read_dir(d)
                .map_err(|e| Error::io(d, "cannot list the shard directory", e))?;
            let mut paths: Vec<PathBuf> = entries
                .flatten()
                .map(|e| e.path())
                .filter(|p| {
                    p.extension().is_some_and(|x| x == "shard")
                        && !p
                            .file_name()
                            .is_some_and(|n| n.to_string_lossy().starts_with('.'))
                })
                .collect();
            paths.sort();
            for p in paths {
                let h = shard::read_header(&p)?;
                headers.push((p, h));
            }
        }
        if headers.is_empty() {
            let list: Vec<String> = dirs.iter().map(|d| d.display().to_string()).collect();
            return Err(Error::verify(
                list.join(", "),
                "no shard files (*.shard) here; run `relume-bake run PIPELINE --shard I/N` first",
            ));
        }
        // One bake: group by bake id and name the shards outside the largest group.
        let mut groups: BTreeMap<&str, Vec<&Path>> = BTreeMap::new();
        for (p, h) in &headers {
            groups.entry(&h.bake).or_default().push(p);
        }
        if groups.len() > 1 {
            let largest = groups.values().map(Vec::len).max().unwrap_or(0);
            let (main, _) = groups
                .iter()
                .find(|(_, v)| v.len() == largest)
                .map(|(k, v)| (k.to_string(), v.len()))
                .unwrap();
            let foreign: Vec<String> = headers
                .iter()
                .filter(|(_, h)| h.bake != main)
                .map(|(p, _)| p.display().to_string())
                .collect();
            return Err(Error::verify(
                &foreign[0],
                format!(
                    "the shards come from {} different bakes (pipeline or input differ); {} {} not part of the bake of the other {largest}: {}. Merge each bake's shards separately",
                    groups.len(),
                    foreign.len(),
                    if foreign.len() == 1 { "is" } else { "are" },
                    foreign.join(", ")
                ),
            ));
        }
        // The pipeline comes from the first shard's header: check that file whole first.
        shard::read(&headers[0].0)?;
        Ok(ShardSet { headers })
    }

    /// The prepared arrays of `stage` (see [`read_prepared`]) from whichever directory holds them.
    pub fn prepared(&self, stage: &str, key: &str) -> Result<Option<Mapped>> {
        let name = prepared_name(stage);
        match self.headers.iter().find(|(_, h)| h.stage == name) {
            Some((p, h)) => {
                let dir = p.parent().unwrap_or(Path::new("."));
                read_prepared(dir, stage, key, &h.bake)
            }
            None => Ok(None),
        }
    }

    /// The pipeline the shards were made from.
    pub fn pipeline(&self) -> &Pipeline {
        &self.headers[0].1.pipeline
    }

    /// The complete, consistent set of shards of `stage` with cache key `key`, in index order;
    /// `None` when there is no shard of `stage` at all.
    pub fn complete(&self, stage: &str, key: &str) -> Result<Option<Vec<PathBuf>>> {
        let of: Vec<&(PathBuf, ShardHeader)> = self
            .headers
            .iter()
            .filter(|(_, h)| h.stage == stage)
            .collect();
        let Some((first_path, first)) = of.first().map(|(p, h)| (p, h)) else {
            return Ok(None);
        };
        for (p, h) in &of {
            if h.key != key {
                return Err(Error::verify(
                    p,
                    format!(
                        "made from other inputs of `{stage}` or by another build of relume ({}): its stage key is {}, this bake's is {}. Re-run that shard",
                        h.relume_version,
                        &h.key[..12],
                        &key[..12]
                    ),
                ));
            }
            if h.count != first.count {
                return Err(Error::verify(
                    p,
                    format!(
                        "is shard {} of {}, but {} is of {}: shards of one stage must come from one split",
                        h.index,
                        h.count,
                        first_path.display(),
                        first.count
                    ),
                ));
            }
        }
        let count = first.count as usize;
        let mut slots: Vec<Option<&PathBuf>> = vec![None; count];
        for (p, h) in &of {
            let i = h.index as usize;
            if i >= count {
                return Err(Error::verify(
                    p,
                    format!("index {i} is not below its count {count}"),
                ));
            }
            if let Some(other) = slots[i] {
                return Err(Error::verify(
                    p,
                    format!(
                        "duplicates shard {i} of {count} of `{stage}`, already in {}: remove one",
                        other.display()
                    ),
                ));
            }
            slots[i] = Some(p);
        }
        let missing: Vec<String> = slots
            .iter()
            .enumerate()
            .filter(|(_, s)| s.is_none())
            .map(|(i, _)| shard::file_name(stage, i as u32, count as u32))
            .collect();
        if !missing.is_empty() {
            return Err(Error::verify(
                first_path.parent().unwrap_or(Path::new(".")),
                format!(
                    "{} of {count} shards of `{stage}` missing: {}. Run `relume-bake run PIPELINE --shard I/{count}` for each",
                    missing.len(),
                    missing.join(", ")
                ),
            ));
        }
        Ok(Some(
            slots.into_iter().map(|s| s.unwrap().clone()).collect(),
        ))
    }
}

/// Parse `I/N` (0 ≤ I < N).
pub fn parse_shard(text: &str) -> std::result::Result<(usize, usize), String> {
    let (i, n) = text
        .split_once('/')
        .ok_or_else(|| format!("`{text}`: expected I/N, e.g. 0/4"))?;
    let (i, n): (usize, usize) = (
        i.trim()
            .parse()
            .map_err(|_| format!("`{i}` is not a shard index"))?,
        n.trim()
            .parse()
            .map_err(|_| format!("`{n}` is not a shard count"))?,
    );
    if n == 0 || i >= n {
        return Err(format!(
            "shard {i}/{n}: the index must be below the count (0/{n} .. {}/{n})",
            n.max(1) - 1
        ));
    }
    Ok((i, n))
}

/// The shard this process computes when the command line names none: Slurm's
/// `SLURM_ARRAY_TASK_ID` with `SLURM_ARRAY_TASK_COUNT` (or `shards`), or Kubernetes'
/// `JOB_COMPLETION_INDEX` with `shards`. `env` reads a variable.
pub fn shard_from_env(
    shards: Option<usize>,
    env: impl Fn(&str) -> Option<String>,
) -> std::result::Result<Option<(usize, usize, &'static str)>, String> {
    let num = |name: &str| -> std::result::Result<Option<usize>, String> {
        env(name)
            .map(|v| {
                v.trim()
                    .parse::<usize>()
                    .map_err(|_| format!("{name}={v} is not a number"))
            })
            .transpose()
    };
    let (index, source) = match (num("SLURM_ARRAY_TASK_ID")?, num("JOB_COMPLETION_INDEX")?) {
        (Some(i), _) => (i, "SLURM_ARRAY_TASK_ID"),
        (None, Some(i)) => (i, "JOB_COMPLETION_INDEX"),
        (None, None) if shards.is_some() => {
            return Err(
                "--shards N needs the shard index from SLURM_ARRAY_TASK_ID or JOB_COMPLETION_INDEX (or use --shard I/N)"
                    .into(),
            )
        }
        (None, None) => return Ok(None),
    };
    let count = match (shards, num("SLURM_ARRAY_TASK_COUNT")?) {
        (Some(n), _) => n,
        (None, Some(n)) if source == "SLURM_ARRAY_TASK_ID" => n,
        _ if source == "SLURM_ARRAY_TASK_ID" => return Ok(None), // a plain Slurm job step
        _ => {
            return Err(
                "JOB_COMPLETION_INDEX is set: give the number of shards with --shards N".into(),
            )
        }
    };
    if count == 0 || index >= count {
        return Err(format!("{source}={index} is not below the shard count {count} (Slurm arrays here start at 0: --array=0-{})", count.max(1) - 1));
    }
    Ok(Some((index, count, source)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env<'a>(vars: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |k: &str| {
            vars.iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| v.to_string())
        }
    }

    #[test]
    fn shard_arguments_and_environment() {
        assert_eq!(parse_shard("2/4"), Ok((2, 4)));
        assert!(parse_shard("4/4").is_err());
        assert!(parse_shard("1/0").is_err());
        assert!(parse_shard("x").is_err());
        let slurm = [
            ("SLURM_ARRAY_TASK_ID", "3"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ];
        assert_eq!(
            shard_from_env(None, env(&slurm)),
            Ok(Some((3, 4, "SLURM_ARRAY_TASK_ID")))
        );
        assert_eq!(shard_from_env(None, env(&[])), Ok(None));
        let k8s = [("JOB_COMPLETION_INDEX", "1")];
        assert_eq!(
            shard_from_env(Some(2), env(&k8s)),
            Ok(Some((1, 2, "JOB_COMPLETION_INDEX")))
        );
        assert!(shard_from_env(None, env(&k8s)).is_err());
        assert!(shard_from_env(Some(4), env(&[])).is_err());
        let over = [
            ("SLURM_ARRAY_TASK_ID", "4"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ];
        assert!(shard_from_env(None, env(&over)).is_err());
    }
}
