//! The stages a pipeline can list, with their knobs, and the rules of their order.

use super::plan::{PlanState, PlannedStage};
use super::Pipeline;
use crate::baked::{BakeTransaction, StageRecord};
use crate::error::{Error, Result};
use crate::progress::Progress;
use crate::workspace::Workspace;
use serde::{Deserialize, Serialize};
use std::path::Path;

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

/// One stage of a pipeline with its knobs. Each variant's knobs live beside the stage's code.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Stage {
    /// Simplify the scene into voxel patches (`crate::radiosity::patches`).
    Voxelize(crate::radiosity::stages::VoxelizeKnobs),
    /// Form factors between patches with BVH visibility (`crate::radiosity::formfactor`).
    FormFactors(crate::radiosity::stages::FormFactorsKnobs),
    /// k-bounce or infinite-bounce transport matrix (`crate::radiosity::transport`).
    Transport(crate::radiosity::stages::TransportKnobs),
    /// Greedy reordering of the transport matrix (src/compress/reorder.rs).
    Reorder(crate::compress::stages::ReorderKnobs),
    /// Split, log map and block-compress the transport (src/compress/).
    Encode(crate::compress::stages::EncodeKnobs),
    /// Min/max mipmap of a height map (`minmax_mipmap.exr`).
    MinmaxMipmap(crate::terrain::mipmap_stage::MinmaxMipmapKnobs),
}

/// The name of a stage without its knobs. Declaration order is pipeline order: running a stage
/// alone on a bake invalidates the stages that come after it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum StageKind {
    Voxelize,
    FormFactors,
    Transport,
    Reorder,
    Encode,
    MinmaxMipmap,
}

impl Stage {
    /// Which stage this is.
    pub fn kind(&self) -> StageKind {
        match self {
            Stage::Voxelize(_) => StageKind::Voxelize,
            Stage::FormFactors(_) => StageKind::FormFactors,
            Stage::Transport(_) => StageKind::Transport,
            Stage::Reorder(_) => StageKind::Reorder,
            Stage::Encode(_) => StageKind::Encode,
            Stage::MinmaxMipmap(_) => StageKind::MinmaxMipmap,
        }
    }

    /// The stage's implementation.
    pub fn runner(&self) -> &dyn StageRun {
        match self {
            Stage::Voxelize(k) => k,
            Stage::FormFactors(k) => k,
            Stage::Transport(k) => k,
            Stage::Reorder(k) => k,
            Stage::Encode(k) => k,
            Stage::MinmaxMipmap(k) => k,
        }
    }
}

impl StageKind {
    /// The name used in pipeline files and the manifest.
    pub fn name(self) -> &'static str {
        match self {
            StageKind::Voxelize => "voxelize",
            StageKind::FormFactors => "form_factors",
            StageKind::Transport => "transport",
            StageKind::Reorder => "reorder",
            StageKind::Encode => "encode",
            StageKind::MinmaxMipmap => "minmax_mipmap",
        }
    }

    /// The input kind the stage works on (`"scene"` or `"heightmap"`).
    pub fn input_kind(self) -> &'static str {
        match self {
            StageKind::Voxelize | StageKind::FormFactors | StageKind::Transport => "scene",
            StageKind::Reorder | StageKind::Encode => "scene",
            StageKind::MinmaxMipmap => "heightmap",
        }
    }

    /// Stages that must have run before this one (in this pipeline or an earlier bake).
    pub fn requires(self) -> &'static [StageKind] {
        match self {
            StageKind::Voxelize => &[],
            StageKind::FormFactors => &[StageKind::Voxelize],
            StageKind::Transport => &[StageKind::Voxelize, StageKind::FormFactors],
            StageKind::Reorder | StageKind::Encode => &[StageKind::Transport],
            StageKind::MinmaxMipmap => &[],
        }
    }
}

/// Check that every stage fits the input kind and comes after the stages it needs.
pub(super) fn check_order(path: &Path, pipeline: &Pipeline) -> Result<()> {
    let mut done: Vec<StageKind> = Vec::new();
    for stage in &pipeline.stages {
        let kind = stage.kind();
        if kind.input_kind() != pipeline.input.kind() {
            return Err(Error::input(
                path,
                format!(
                    "stage `{}` works on a {} input, but this pipeline's input is a {}",
                    kind.name(),
                    kind.input_kind(),
                    pipeline.input.kind()
                ),
            ));
        }
        if let Some(missing) = kind.requires().iter().find(|r| !done.contains(r)) {
            return Err(Error::input(
                path,
                format!(
                    "stage `{}` needs `{}` before it; add it earlier in `stages`",
                    kind.name(),
                    missing.name()
                ),
            ));
        }
        if done.contains(&kind) {
            return Err(Error::input(
                path,
                format!("stage `{}` appears twice", kind.name()),
            ));
        }
        done.push(kind);
    }
    Ok(())
}
