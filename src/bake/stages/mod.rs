//! How each pipeline stage runs: a [`StageRun`] per knob struct of `crate::pipeline::knobs`,
//! which takes its inputs from the [`Workspace`], calls the algorithm on plain data, writes its
//! files through `crate::baked`, and estimates its cost for the plan.

mod compress;
mod radiosity;
mod terrain;
mod transport;

use super::estimate::{PlanState, PlannedStage};
use super::workspace::Workspace;
use crate::baked::shard::{Mapped, Payload};
use crate::baked::{BakeTransaction, StageRecord};
use crate::error::Result;
use crate::pipeline::Stage;
use crate::progress::Progress;
use std::path::PathBuf;

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

    /// Can this stage (with these knobs) be split into shards? (docs/scale-out.md)
    fn shardable(&self) -> bool {
        false
    }

    /// Work that one process does once before the shards of this stage (the merge that ends the
    /// previous round): arrays every shard reads (the transport's LU factors).
    fn prepare_shards(&self, _ws: &mut Workspace) -> Result<Option<Payload>> {
        Ok(None)
    }

    /// Compute shard `index` of `count` (with what [`StageRun::prepare_shards`] made): what
    /// part it is (for people), and its arrays.
    fn run_shard(
        &self,
        _ws: &mut Workspace,
        _index: usize,
        _count: usize,
        _prepared: Option<Mapped>,
        _progress: &dyn Progress,
    ) -> Result<(String, Payload)> {
        Err(crate::error::Error::Internal(
            "this stage has no shards".into(),
        ))
    }

    /// Put every shard (the files of a complete set, in index order, each read and verified
    /// one at a time with `crate::baked::shard::read`) together, write the stage's files into
    /// `txn` as [`StageRun::run`] would, and return the same record.
    fn merge_shards(
        &self,
        _ws: &mut Workspace,
        _txn: &mut BakeTransaction,
        _shards: Vec<PathBuf>,
        _prepared: Option<Mapped>,
    ) -> Result<StageRecord> {
        Err(crate::error::Error::Internal(
            "this stage has no shards".into(),
        ))
    }

    /// Estimated working bytes of [`StageRun::prepare_shards`] (after `estimate` updated
    /// `state`), besides what earlier stages keep.
    fn estimate_prepare(&self, _state: &PlanState) -> u64 {
        0
    }

    /// Estimated peak bytes of shard `index` of `count` (after `estimate` updated `state`).
    fn estimate_shard(&self, _state: &PlanState, _index: usize, _count: usize) -> u64 {
        0
    }
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
        Stage::Themes(k) => k,
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
