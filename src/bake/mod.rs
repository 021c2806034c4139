//! Running a pipeline: load the input, check the plan against the memory budget, run each stage
//! in order into a [`BakeTransaction`], write the manifest and swap the bake into place.

pub mod cache;
pub mod estimate;
pub mod plan;
pub mod report;
pub mod shard;
pub mod stages;
pub mod workspace;

pub use estimate::{Measured, PlanState, PlannedStage};
pub use plan::{plan, Plan};

use crate::baked::{self, manifest::hash_file, BakeTransaction, FileRecord, Manifest, StageRecord};
use crate::error::{Error, Result};
use crate::limits;
use crate::load::{load_input, LoadedInput};
use crate::pipeline::{Pipeline, Stage};
use crate::progress::Progress;
use cache::StageCache;
use serde::Serialize;
pub use shard::{ShardWritten, Sharding};
use stages::runner;
use std::path::{Path, PathBuf};
use std::time::Instant;
use workspace::Workspace;

/// Knobs of a bake that are not part of the pipeline (they do not change the output).
#[derive(Clone, Debug)]
pub struct BakeOptions {
    /// Refuse to start when the estimated peak memory exceeds this many bytes.
    pub max_memory: u64,
    /// Root of the stage cache (`cache`): `None` runs every stage. The CLI's default is
    /// `.relume-cache` beside the output.
    pub cache: Option<PathBuf>,
    /// Run every stage even when the output is up to date or the cache holds them (the cache is
    /// refreshed with what runs).
    pub force: bool,
    /// Bake whole, compute one shard, or merge shards (docs/scale-out.md).
    pub sharding: Sharding,
}

impl Default for BakeOptions {
    fn default() -> Self {
        BakeOptions {
            max_memory: limits::default_max_memory(),
            cache: None,
            force: false,
            sharding: Sharding::Whole,
        }
    }
}

/// What a bake did, for people and `--json` (times live here, never in the manifest).
#[derive(Clone, Debug, Serialize)]
pub struct BakeReport {
    pub output: PathBuf,
    /// The output already held this bake (same pipeline, input, version; every file verified):
    /// nothing was run or written.
    pub up_to_date: bool,
    pub stages: Vec<StageTiming>,
    pub files: Vec<FileRecord>,
    pub warnings: Vec<String>,
    /// The largest peak memory the plan estimated for a stage that ran (re-planned before each
    /// stage with the sizes measured so far).
    pub estimated_peak_bytes: u64,
    /// The process's measured peak resident memory (Linux), for comparison with the estimate.
    pub peak_rss_bytes: Option<u64>,
    /// `run --shard`: the shard this process wrote (nothing else was written).
    pub shard: Option<ShardWritten>,
    /// `merge`: the stage whose shards are still to be computed (a next round of
    /// `run --shard`); the stages merged so far are kept in the stage cache, the output is not
    /// written yet.
    pub needs_shards: Option<String>,
}

/// Wall time and outputs of one stage.
#[derive(Clone, Debug, Serialize)]
pub struct StageTiming {
    pub stage: String,
    pub seconds: f64,
    /// Taken from the stage cache instead of run.
    pub cached: bool,
    /// The plan's peak memory for this stage (re-planned with the sizes measured before it).
    pub estimated_peak_bytes: u64,
    /// The process's peak resident memory while the stage ran (Linux; `None` elsewhere).
    pub peak_rss_bytes: Option<u64>,
    pub outputs: Vec<String>,
    pub report: std::collections::BTreeMap<String, f64>,
}

/// Read and check the files stages name (a `Themes` stage's theme set) before any work, so a
/// missing or malformed one stops the bake before the input is loaded.
fn check_stage_files(pipeline: &Pipeline) -> Result<()> {
    for stage in &pipeline.stages {
        if let crate::pipeline::Stage::Themes(k) = stage {
            let text = std::fs::read_to_string(&k.file).map_err(|e| {
                crate::error::Error::io(&k.file, "cannot read the Themes stage's theme set", e)
            })?;
            crate::load::themes::parse_themes(&k.file, &text)?;
        }
    }
    Ok(())
}

/// The checks of the `Themes` stages that need the loaded input (georeferenced polygons need the
/// height map's georeference), made before any stage runs.
fn check_stage_input(pipeline: &Pipeline, input: &LoadedInput) -> Result<()> {
    let LoadedInput::HeightMap(map, info) = input else {
        return Ok(());
    };
    let name = format!(
        "the pipeline's height map `{}`",
        pipeline.input.path().display()
    );
    for stage in &pipeline.stages {
        if let Stage::Themes(k) = stage {
            let given = crate::load::themes::GivenHeightMap {
                map,
                georef: info.georef.as_ref(),
                name: &name,
            };
            crate::load::themes::check_heightmap(&k.file, given)?;
        }
    }
    Ok(())
}

/// Bake `pipeline` into `output`. On any error nothing is written and a previous bake at
/// `output` is left as it was.
///
/// Before each stage that runs (is not taken from the cache), the rest of the pipeline is
/// planned again with the sizes measured so far (the real patch count after voxelize) and the
/// plan's peak is checked against `opts.max_memory`.
///
/// This is the library's entry point for a bake: `relume-bake run` is this function with
/// progress bars. `examples/bake_scene.rs` shows it end to end.
pub fn run_pipeline(
    pipeline: &Pipeline,
    output: &Path,
    opts: &BakeOptions,
    progress: &dyn Progress,
) -> Result<BakeReport> {
    let t0 = Instant::now();
    limits::baseline_rss();
    let merge_set = match &opts.sharding {
        Sharding::Merge { dirs } => Some(shard::ShardSet::scan(dirs)?),
        _ => None,
    };
    check_stage_files(pipeline)?;
    progress.begin("load", 0);
    let input = load_input(&pipeline.input)?;
    check_stage_input(pipeline, &input)?;
    progress.finish();
    let mut warnings = Vec::new();
    if let LoadedInput::Scene(_, w) = &input {
        for m in &w.messages {
            progress.warn(m);
            warnings.push(m.clone());
        }
    }
    let mut txn = BakeTransaction::begin(output)?;
    let load_record = write_input(&mut txn, &input)?;
    let mut measured = Measured::default();
    let mut timings = vec![timing(&load_record, t0, false)];
    let mut records = vec![load_record];
    let plan_input = plan::PlanInput::of(&input);

    let mut ws = Workspace::new();
    ws.set_memory_budget(opts.max_memory);
    ws.read_missing_from(txn.staging_dir());
    match input {
        LoadedInput::Scene(scene, _) => ws.set_scene(scene),
        LoadedInput::HeightMap(map, info) => {
            ws.set_heightmap(map);
            ws.set_georef(info.georef);
        }
    }
    let cache = opts
        .cache
        .as_deref()
        .map(|root| StageCache::open(root, output));
    let mut keys = Vec::new();
    let mut ran_any = false;
    let mut estimated_peak =
        plan::plan_measured(pipeline, &plan_input, output, &measured).stages[0].peak_bytes;
    timings[0].estimated_peak_bytes = estimated_peak;
    timings[0].peak_rss_bytes = limits::peak_rss();
    for (i, stage) in pipeline.stages.iter().enumerate() {
        let t = Instant::now();
        let mut stage_estimate = 0;
        let before = txn.files();
        let key = StageCache::key(stage, &before, ws.georef()?);
        let hit = cache
            .as_ref()
            .filter(|_| !opts.force)
            .and_then(|c| c.lookup(&key));
        let (rec, cached) = match hit {
            Some(hit) => (hit.apply(&mut txn)?, true),
            None => {
                let sharding = match &opts.sharding {
                    Sharding::Shard { index, count, .. } => Some((*index, *count)),
                    _ => None,
                };
                if sharding.is_some() && !pipeline.stages[i..].iter().any(|s| runner(s).shardable())
                {
                    // Every shardable stage is in the cache: the rest is the merge's.
                    return Ok(partial_report(output, timings, warnings, estimated_peak));
                }
                let rest = plan::plan_measured(pipeline, &plan_input, output, &measured);
                // The first stage that runs answers for the load too; a shard answers for its
                // own part only.
                let peak = match sharding {
                    Some((index, count)) if runner(stage).shardable() => {
                        plan::shard_peak(pipeline, &plan_input, &measured, i, index, count)
                    }
                    _ => rest.peak_from(if ran_any { i + 1 } else { 0 }),
                };
                ran_any = true;
                let what = format!("the rest of this bake (from `{}`)", stage.kind().name());
                limits::check_memory(&what, peak, opts.max_memory)?;
                estimated_peak = estimated_peak.max(peak);
                stage_estimate = rest.stages[i + 1].peak_bytes;
                limits::reset_peak_rss();
                let run = runner(stage);
                let name = stage.kind().name();
                let rec = match (&opts.sharding, run.shardable()) {
                    (Sharding::Shard { index, count, dir }, true) => {
                        if cache.is_none() {
                            return Err(Error::knob(
                                "--shard needs the stage cache (drop --no-cache): the merge and the next round of shards find the stages all shards share there",
                            ));
                        }
                        let at = shard::ShardAt {
                            pipeline,
                            stage: name,
                            key: &key,
                            index: *index,
                            count: *count,
                            dir,
                        };
                        let written = at.compute(run, &mut ws, progress)?;
                        let mut tm = timing(&records[0], t, false);
                        tm.stage = name.into();
                        tm.outputs = vec![written.path.display().to_string()];
                        tm.peak_rss_bytes = limits::peak_rss();
                        timings.push(tm);
                        let report = partial_report(output, timings, warnings, estimated_peak);
                        return Ok(BakeReport {
                            shard: Some(written),
                            ..report
                        });
                    }
                    (Sharding::Merge { .. }, true) => {
                        let set = merge_set.as_ref().expect("scanned for a merge");
                        let Some(shards) = set.complete(name, &key)? else {
                            // The next round: what its shards share is made here, once.
                            if let Some(p) = run.prepare_shards(&mut ws)? {
                                let Sharding::Merge { dirs } = &opts.sharding else {
                                    unreachable!()
                                };
                                shard::write_prepared(&dirs[0], pipeline, name, &key, &p)?;
                            }
                            let report = partial_report(output, timings, warnings, estimated_peak);
                            return Ok(BakeReport {
                                needs_shards: Some(name.into()),
                                ..report
                            });
                        };
                        let prepared = set.prepared(name, &key)?;
                        run.merge_shards(&mut ws, &mut txn, shards, prepared)?
                    }
                    _ => run.run(&mut ws, &mut txn, progress)?,
                };
                if let Some(c) = &cache {
                    if let Err(e) = c.store(&key, stage, &rec, &before, &txn) {
                        let w = format!("the stage cache is not kept: {e}");
                        progress.warn(&w);
                        warnings.push(w);
                    }
                }
                (rec, false)
            }
        };
        measured.observe(&rec);
        keys.push(key);
        let mut tm = timing(&rec, t, cached);
        if !cached {
            tm.estimated_peak_bytes = stage_estimate;
            tm.peak_rss_bytes = limits::peak_rss();
        }
        timings.push(tm);
        records.push(rec);
    }

    if matches!(opts.sharding, Sharding::Shard { .. }) {
        // Every stage was in the cache: nothing to shard, the output is the merge's to write.
        return Ok(partial_report(output, timings, warnings, estimated_peak));
    }
    let (bytes, sha256) = hash_file(pipeline.input.path())?;
    let input_name = pipeline
        .input
        .path()
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut manifest = Manifest {
        format_version: baked::FORMAT_VERSION,
        relume_version: env!("CARGO_PKG_VERSION").to_string(),
        pipeline: pipeline.clone(),
        input: FileRecord {
            name: input_name,
            bytes,
            sha256,
        },
        stages: records,
        files: Vec::new(),
    };
    let files = txn.files();
    let all_cached = cache.is_some() && timings.iter().skip(1).all(|t| t.cached);
    manifest.files = files.clone();
    let up_to_date = all_cached && holds(output, &manifest, txn.staging_dir());
    if up_to_date {
        drop(txn);
    } else {
        txn.commit(manifest)?;
    }
    if let Some(c) = &cache {
        c.retain(&keys);
    }
    // Each stage's peak was measured from a reset: the bake's peak is the largest.
    let peak_rss = timings.iter().filter_map(|t| t.peak_rss_bytes).max();
    Ok(BakeReport {
        output: output.to_path_buf(),
        up_to_date,
        stages: if up_to_date { Vec::new() } else { timings },
        files,
        warnings,
        estimated_peak_bytes: estimated_peak,
        peak_rss_bytes: peak_rss,
        shard: None,
        needs_shards: None,
    })
}

/// The report of a bake that stopped before its commit on purpose: a shard was written, or a
/// merge needs the next round of shards.
fn partial_report(
    output: &Path,
    stages: Vec<StageTiming>,
    warnings: Vec<String>,
    estimated_peak_bytes: u64,
) -> BakeReport {
    BakeReport {
        output: output.to_path_buf(),
        up_to_date: false,
        // The stage that stopped (a shard, a merge's preparation) has no timing of its own: the
        // peak since its start counts too.
        peak_rss_bytes: stages
            .iter()
            .filter_map(|t| t.peak_rss_bytes)
            .chain(limits::peak_rss())
            .max(),
        stages,
        files: Vec::new(),
        warnings,
        estimated_peak_bytes,
        shard: None,
        needs_shards: None,
    }
}

/// Does the baked directory at `output` have exactly this manifest, with every file intact? A
/// file of `output` that is the very file staged in `staged` (both hard links of one cache entry,
/// whose hashes the lookup checked) is not hashed again: 0.51 s → 0.20 s for an up-to-date
/// `cornell-4k` (257 MiB).
fn holds(output: &Path, manifest: &Manifest, staged: &Path) -> bool {
    Manifest::read(output).is_ok_and(|m| m == *manifest)
        && baked::manifest::verify_files(
            output,
            manifest
                .files
                .iter()
                .filter(|f| !same_file(&output.join(&f.name), &staged.join(&f.name))),
        )
        .is_empty()
}

/// Are `a` and `b` one file (the same inode of the same device)?
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (std::fs::metadata(a), std::fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (a, b);
        false
    }
}

fn timing(record: &StageRecord, since: Instant, cached: bool) -> StageTiming {
    StageTiming {
        stage: record.stage.clone(),
        seconds: since.elapsed().as_secs_f64(),
        cached,
        estimated_peak_bytes: 0,
        peak_rss_bytes: None,
        outputs: record.outputs.clone(),
        report: record.report.clone(),
    }
}

/// Store the input in its canonical baked form and describe it.
fn write_input(txn: &mut BakeTransaction, input: &LoadedInput) -> Result<StageRecord> {
    let mut rec = StageRecord {
        stage: "load".into(),
        ..Default::default()
    };
    match input {
        LoadedInput::Scene(scene, _) => {
            baked::scene::write(txn, scene)?;
            rec.outputs.push(baked::scene::FILE.into());
            if !scene.viewpoints.is_empty() {
                rec.outputs.push(baked::scene::VIEWS_FILE.into());
            }
            rec.report
                .insert("vertices".into(), scene.positions.len() as f64);
            rec.report
                .insert("triangles".into(), scene.triangles.len() as f64);
            rec.report.insert(
                "degenerate_triangles".into(),
                scene.degenerate_triangles().count() as f64,
            );
            rec.report
                .insert("materials".into(), scene.materials.len() as f64);
            rec.report
                .insert("lights".into(), scene.lights.len() as f64);
            rec.facts.insert("grey".into(), scene.is_grey().to_string());
        }
        LoadedInput::HeightMap(map, info) => {
            baked::heightmap::write(txn, map)?;
            rec.outputs.push(baked::heightmap::FILE.into());
            let (lo, hi) = map.min_max();
            rec.report.insert("width".into(), map.width as f64);
            rec.report.insert("height".into(), map.height as f64);
            rec.report.insert("cell_size_x".into(), map.cell_size[0]);
            rec.report.insert("cell_size_y".into(), map.cell_size[1]);
            rec.report.insert("height_scale".into(), map.height_scale);
            rec.report.insert("min_height".into(), lo as f64);
            rec.report.insert("max_height".into(), hi as f64);
            rec.report
                .insert("nodata_filled".into(), info.nodata_count as f64);
            rec.facts.insert(
                "source_format".into(),
                format!("{} {}", info.format, info.sample),
            );
            rec.facts.insert("units".into(), "metres".into());
            if let Some(g) = &info.georef {
                let text = ron::to_string(g).expect("a georeference serialises");
                let fact = baked::heightmap::GEOREFERENCE_FACT;
                rec.facts.insert(fact.into(), text);
            }
        }
    }
    Ok(rec)
}

/// Run one stage alone on an existing bake at `dir`, replacing it atomically. Stages that come
/// after `stage` in pipeline order are dropped from the bake (their inputs changed), and the
/// manifest's pipeline is updated so that it still describes how to reproduce the bake.
pub fn run_stage_on(dir: &Path, stage: Stage, progress: &dyn Progress) -> Result<BakeReport> {
    run_stage_on_with(dir, stage, &BakeOptions::default(), progress)
}

/// [`run_stage_on`] with options (the memory budget).
pub fn run_stage_on_with(
    dir: &Path,
    stage: Stage,
    opts: &BakeOptions,
    progress: &dyn Progress,
) -> Result<BakeReport> {
    let manifest = Manifest::read(dir)?;
    let kind = stage.kind();
    let mpath = dir.join(baked::MANIFEST);
    if kind.input_kind() != manifest.pipeline.input.kind() {
        return Err(Error::input(
            &mpath,
            format!(
                "stage `{}` works on a {} bake, this is a {} bake",
                kind.name(),
                kind.input_kind(),
                manifest.pipeline.input.kind()
            ),
        ));
    }
    let mut pipeline = manifest.pipeline.clone();
    pipeline.stages.retain(|s| s.kind() < kind);
    if let Some(missing) = kind
        .requires()
        .iter()
        .find(|r| !pipeline.stages.iter().any(|s| s.kind() == **r))
    {
        return Err(Error::input(
            dir,
            format!(
                "stage `{}` needs `{}` to have run on this bake first",
                kind.name(),
                missing.name()
            ),
        ));
    }
    let kept: Vec<&StageRecord> = manifest
        .stages
        .iter()
        .filter(|r| r.stage == "load" || pipeline.stages.iter().any(|s| s.kind().name() == r.stage))
        .collect();
    let mut txn = BakeTransaction::begin(dir)?;
    for rec in &kept {
        for f in &rec.outputs {
            let file = manifest.file(f).ok_or_else(|| {
                Error::verify(
                    dir.join(f),
                    "listed as a stage output but not in the manifest's files",
                )
            })?;
            txn.carry(dir, file)?;
        }
    }
    let mut records: Vec<StageRecord> = kept.into_iter().cloned().collect();
    let mut ws = Workspace::over_bake(dir, manifest.clone());
    ws.set_memory_budget(opts.max_memory);
    let t = Instant::now();
    let rec = runner(&stage).run(&mut ws, &mut txn, progress)?;
    let timings = vec![timing(&rec, t, false)];
    records.push(rec);
    pipeline.stages.push(stage);
    let files = txn.files();
    let new_manifest = Manifest {
        pipeline,
        stages: records,
        files: Vec::new(),
        ..manifest
    };
    txn.commit(new_manifest)?;
    Ok(BakeReport {
        output: dir.to_path_buf(),
        up_to_date: false,
        stages: timings,
        files,
        warnings: Vec::new(),
        estimated_peak_bytes: 0,
        peak_rss_bytes: limits::peak_rss(),
        shard: None,
        needs_shards: None,
    })
}
