//! `relume-bake plan`: the stages a pipeline would run, with estimated peak memory and output
//! size, computed from the loaded input without writing anything. `run` checks the same estimate
//! against `--max-memory` before it allocates.

use super::estimate::{Measured, PlanState, PlannedStage};
use super::stages::runner;
use crate::load::LoadedInput;
use crate::pipeline::{Pipeline, Stage};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// What a pipeline would do.
#[derive(Clone, Debug, Serialize)]
pub struct Plan {
    pub input: String,
    pub input_kind: &'static str,
    pub output: PathBuf,
    pub stages: Vec<PlannedStage>,
    /// The largest peak over all stages (stages run one after another).
    pub peak_bytes: u64,
    /// Total size of the baked directory.
    pub output_bytes: u64,
}

impl Plan {
    /// The plan as a table for people (`relume-bake plan`).
    pub fn to_text(&self, pipeline: &Path) -> String {
        use crate::limits::{default_max_memory, human_bytes};
        let mut t = format!(
            "pipeline {}: {} input {}\noutput   {}\n{:<16} {:>12} {:>12}  notes\n",
            pipeline.display(),
            self.input_kind,
            self.input,
            self.output.display(),
            "stage",
            "peak memory",
            "writes"
        );
        for s in &self.stages {
            t += &format!(
                "{:<16} {:>12} {:>12}  {}\n",
                s.stage,
                human_bytes(s.peak_bytes),
                human_bytes(s.output_bytes),
                s.notes
            );
        }
        t += &format!(
            "total: peak {} (budget {}), writes {}\n",
            human_bytes(self.peak_bytes),
            human_bytes(default_max_memory()),
            human_bytes(self.output_bytes)
        );
        t += &format!(
            "peaks include relume's own {}; `run` plans the rest again before each stage with the sizes measured so far (the real patch count after voxelize) and stops before a stage that would go over the budget\n",
            human_bytes(crate::limits::baseline_rss())
        );
        t
    }
}

/// What the plan needs to know of the loaded input.
#[derive(Clone, Debug)]
pub struct PlanInput {
    state: PlanState,
    load: PlannedStage,
}

impl PlanInput {
    /// Sizes of a loaded input.
    pub fn of(input: &LoadedInput) -> Self {
        let mut state = PlanState::default();
        let load = match input {
            LoadedInput::Scene(scene, _) => {
                let v = scene.positions.len() as u64;
                let t = scene.triangles.len() as u64;
                state.triangles = t;
                state.channels = if scene.is_grey() { 1 } else { 3 };
                let texels = |x: &crate::scene::texture::Texture| x.width as u64 * x.height as u64;
                state.largest_texture_texels = scene.textures.iter().map(texels).max().unwrap_or(0);
                let texture_bytes: u64 = scene.textures.iter().map(|x| 4 * texels(x)).sum();
                let bytes = v * 12
                    + t * 20
                    + scene.materials.len() as u64 * 64
                    + scene.uvs.len() as u64 * 8
                    + texture_bytes;
                state.resident_bytes = bytes;
                PlannedStage {
                    stage: "load".into(),
                    peak_bytes: bytes * 2,
                    output_bytes: bytes,
                    notes: format!("{v} vertices, {t} triangles"),
                }
            }
            LoadedInput::HeightMap(map, info) => {
                let texels = (map.width * map.height) as u64;
                let [w, h] = info.source_size;
                state.map_size = (map.width as u64, map.height as u64);
                state.resident_bytes = texels * 4;
                // The decoded samples, their f64 copy, the f32 heights and the validity mask of
                // the file's whole grid, and the downsampled map when there is one.
                let sample_bytes = match info.sample.as_str() {
                    "u8" => 1,
                    "u16" | "i16" => 2,
                    "f32" | "i32" | "u32" => 4,
                    _ => 8,
                };
                PlannedStage {
                    stage: "load".into(),
                    peak_bytes: (w * h) as u64 * (13 + sample_bytes)
                        + if texels < (w * h) as u64 {
                            texels * 4
                        } else {
                            0
                        },
                    output_bytes: texels * 4,
                    notes: format!("{}x{} texels (file {w}x{h})", map.width, map.height),
                }
            }
        };
        PlanInput { state, load }
    }
}

impl Plan {
    /// The largest peak of the plan's stages from index `first` on (0 is the load).
    pub fn peak_from(&self, first: usize) -> u64 {
        self.stages
            .iter()
            .skip(first)
            .map(|s| s.peak_bytes)
            .max()
            .unwrap_or(0)
    }
}

/// Estimate the pipeline on a loaded input, before any stage ran.
pub fn plan(pipeline: &Pipeline, input: &LoadedInput, output: &Path) -> Plan {
    plan_measured(
        pipeline,
        &PlanInput::of(input),
        output,
        &Measured::default(),
    )
}

/// Estimate the pipeline with what the stages that already ran measured.
pub fn plan_measured(
    pipeline: &Pipeline,
    input: &PlanInput,
    output: &Path,
    measured: &Measured,
) -> Plan {
    let mut state = input.state.clone();
    state.measured_patches = measured.patches;
    let mut stages = vec![input.load.clone()];
    for stage in &pipeline.stages {
        stages.push(estimate(stage, &mut state));
    }
    for s in &mut stages {
        s.peak_bytes += crate::limits::baseline_rss();
    }
    Plan {
        input: pipeline.input.path().display().to_string(),
        input_kind: pipeline.input.kind(),
        output: output.to_path_buf(),
        peak_bytes: stages.iter().map(|s| s.peak_bytes).max().unwrap_or(0),
        output_bytes: stages.iter().map(|s| s.output_bytes).sum(),
        stages,
    }
}

fn estimate(stage: &Stage, state: &mut PlanState) -> PlannedStage {
    // A stage's own estimate covers its working memory; what earlier stages keep resident adds.
    let resident = state.resident_bytes;
    let mut planned = runner(stage).estimate(state);
    planned.peak_bytes += resident;
    planned
}

/// Estimated peak bytes of shard `index` of `count` of the stage at `stage_index` (a shardable
/// one): what earlier stages keep resident plus the shard's own working memory.
pub fn shard_peak(
    pipeline: &Pipeline,
    input: &PlanInput,
    measured: &Measured,
    stage_index: usize,
    index: usize,
    count: usize,
) -> u64 {
    let mut state = input.state.clone();
    state.measured_patches = measured.patches;
    for stage in &pipeline.stages[..stage_index] {
        estimate(stage, &mut state);
    }
    let stage = &pipeline.stages[stage_index];
    // The stage's own estimate sets the sizes it depends on (patches, channels).
    let resident = state.resident_bytes;
    let mut after = state.clone();
    runner(stage).estimate(&mut after);
    resident + runner(stage).estimate_shard(&after, index, count) + crate::limits::baseline_rss()
}

/// Per-shard and merge estimates for a bake split `count` ways (`plan --shards N`).
#[derive(Clone, Debug, Serialize)]
pub struct ShardPlan {
    /// Rounds of shards, one per shardable stage, in order.
    pub rounds: Vec<ShardRound>,
    /// Estimated peak of a merge (the stages that are not split, and the assembly of each
    /// round's shards).
    pub merge_peak_bytes: u64,
}

impl ShardPlan {
    /// The split plan as text for people (`plan --shards N`).
    pub fn to_text(&self) -> String {
        use crate::limits::human_bytes;
        if self.rounds.is_empty() {
            return "shards: no stage of this pipeline is split (form_factors, or transport with bounces: Infinite)\n".into();
        }
        let mut t = String::from("\nsplit     stage            shard peak  shard file\n");
        for (r, s) in self.rounds.iter().enumerate() {
            t += &format!(
                "round {}   {:<16} {:>10}  {:>10}  x {}\n",
                r + 1,
                s.stage,
                human_bytes(s.shard_peak_bytes),
                human_bytes(s.shard_bytes),
                s.count
            );
        }
        t += &format!(
            "merge peak {} ({} round(s): `run --shard I/N` for every I, then `merge`, per round)\n",
            human_bytes(self.merge_peak_bytes),
            self.rounds.len()
        );
        t
    }
}

/// One shardable stage split `count` ways.
#[derive(Clone, Debug, Serialize)]
pub struct ShardRound {
    pub stage: String,
    pub count: usize,
    /// The largest estimated peak of one shard.
    pub shard_peak_bytes: u64,
    /// The largest estimated shard file.
    pub shard_bytes: u64,
}

/// Plan a bake split into `count` shards per shardable stage.
pub fn plan_shards(
    pipeline: &Pipeline,
    input: &PlanInput,
    measured: &Measured,
    count: usize,
) -> ShardPlan {
    let base = crate::limits::baseline_rss();
    let mut state = input.state.clone();
    state.measured_patches = measured.patches;
    let mut rounds = Vec::new();
    let mut merge_peak = input.load.peak_bytes + base;
    for (i, stage) in pipeline.stages.iter().enumerate() {
        let resident = state.resident_bytes;
        let planned = estimate(stage, &mut state);
        if !runner(stage).shardable() {
            merge_peak = merge_peak.max(planned.peak_bytes + base);
            continue;
        }
        let peak = (0..count)
            .map(|k| shard_peak(pipeline, input, measured, i, k, count))
            .max()
            .unwrap_or(0);
        // The merge holds what earlier stages keep, the assembled output and its working copy
        // (the reciprocity average copies F) or the shard being read; the merge before this
        // round prepares what its shards share (the transport's factors).
        let prepare = runner(stage).estimate_prepare(&state);
        merge_peak = merge_peak
            .max(resident + 2 * planned.output_bytes + base)
            .max(resident + prepare + base);
        rounds.push(ShardRound {
            stage: stage.kind().name().into(),
            count,
            shard_peak_bytes: peak,
            shard_bytes: planned.output_bytes.div_ceil(count as u64) + 4096,
        });
    }
    ShardPlan {
        rounds,
        merge_peak_bytes: merge_peak,
    }
}
