//! `relume-bake plan`: the stages a pipeline would run, with estimated peak memory and output
//! size, computed from the loaded input without writing anything. `run` checks the same estimate
//! against `--max-memory` before it allocates.

use super::estimate::{PlanState, PlannedStage};
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
        t
    }
}

/// Estimate the pipeline on a loaded input.
pub fn plan(pipeline: &Pipeline, input: &LoadedInput, output: &Path) -> Plan {
    let mut state = PlanState::default();
    let load = match input {
        LoadedInput::Scene(scene, _) => {
            let v = scene.positions.len() as u64;
            let t = scene.triangles.len() as u64;
            state.triangles = t;
            state.channels = if scene.is_grey() { 1 } else { 3 };
            let bytes = v * 12 + t * 20 + scene.materials.len() as u64 * 64;
            state.resident_bytes = bytes;
            PlannedStage {
                stage: "load".into(),
                peak_bytes: bytes * 2,
                output_bytes: bytes,
                notes: format!("{v} vertices, {t} triangles"),
            }
        }
        LoadedInput::HeightMap(map, _) => {
            let texels = (map.width * map.height) as u64;
            state.map_size = (map.width as u64, map.height as u64);
            state.resident_bytes = texels * 4;
            PlannedStage {
                stage: "load".into(),
                peak_bytes: texels * 13,
                output_bytes: texels * 4,
                notes: format!("{}x{} texels", map.width, map.height),
            }
        }
    };
    let mut stages = vec![load];
    for stage in &pipeline.stages {
        stages.push(estimate(stage, &mut state));
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
