//! What a stage's estimate says and what it passes on to the next stage's estimate.

use serde::Serialize;

/// One stage of a plan (`super::plan::Plan`).
#[derive(Clone, Debug, Serialize)]
pub struct PlannedStage {
    pub stage: String,
    /// Estimated peak memory of the stage, in bytes, including what it keeps from earlier stages.
    pub peak_bytes: u64,
    /// Estimated bytes the stage writes.
    pub output_bytes: u64,
    /// What the estimate is based on.
    pub notes: String,
}

/// Sizes that later stages' estimates depend on, updated stage by stage.
#[derive(Clone, Debug, Default)]
pub struct PlanState {
    /// Bytes held in memory from earlier stages that later stages keep using.
    pub resident_bytes: u64,
    /// Triangles of a scene input.
    pub triangles: u64,
    /// Texels of the largest texture of a scene input (0 when untextured).
    pub largest_texture_texels: u64,
    /// Width and height of a height-map input.
    pub map_size: (u64, u64),
    /// Estimated patch count after voxelisation.
    pub patches: u64,
    /// Colour channels the transport needs (1 for grey scenes, 3 otherwise).
    pub channels: u64,
    /// The patch count measured by a voxelize that already ran (replaces the estimate).
    pub measured_patches: Option<u64>,
}

/// Sizes measured by the stages that already ran, for planning the rest of a bake.
#[derive(Clone, Debug, Default)]
pub struct Measured {
    /// Patches `voxelize` made.
    pub patches: Option<u64>,
}

impl Measured {
    /// Take what `rec` measured.
    pub fn observe(&mut self, rec: &crate::baked::StageRecord) {
        if rec.stage == "voxelize" {
            self.patches = rec.report.get("patches").map(|&p| p as u64);
        }
    }
}
