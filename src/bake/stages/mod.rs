//! How each pipeline stage runs: a [`StageRun`] per knob struct of `crate::pipeline::knobs`,
//! which takes its inputs from the [`Workspace`], calls the algorithm on plain data, writes its
//! files through `crate::baked`, and estimates its cost for the plan.

mod compress;
mod radiosity;
mod terrain;

use super::estimate::{PlanState, PlannedStage};
use super::workspace::Workspace;
use crate::baked::{BakeTransaction, StageRecord};
use crate::error::Result;
use crate::pipeline::Stage;
use crate::progress::Progress;

/// What every stage's knob struct implements: run over a [`Workspace`], and estimate its cost.
pub trait StageRun {
    /// Run the stage: take inputs from `ws`, write files into `txn`, leave artifacts in `ws` for
    /// later stages, and return the record (outputs and deterministic measurements).
    fn run(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        progress: &dyn Progress,
    ) -> Result<StageRecord>;

    /// Estimate peak memory and output bytes, updating `state` for later stages.
    fn estimate(&self, state: &mut PlanState) -> PlannedStage;
}

/// The implementation of a stage.
pub fn runner(stage: &Stage) -> &dyn StageRun {
    match stage {
        Stage::Voxelize(k) => k,
        Stage::FormFactors(k) => k,
        Stage::Transport(k) => k,
        Stage::Reorder(k) => k,
        Stage::Encode(k) => k,
        Stage::MinmaxMipmap(k) => k,
        Stage::HorizonMaps(k) => k,
    }
}

/// A stage record with its name and outputs.
fn record(stage: &str, outputs: &[&str]) -> StageRecord {
    StageRecord {
        stage: stage.into(),
        outputs: outputs.iter().map(|s| s.to_string()).collect(),
        ..Default::default()
    }
}
