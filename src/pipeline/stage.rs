//! The stages a pipeline can list, with their knobs ([`super::knobs`]), and the rules of their
//! order. How a stage runs lives in `crate::bake::stages`.

use super::knobs::{
    EncodeKnobs, FormFactorsKnobs, HorizonMapsKnobs, MinmaxMipmapKnobs, ReorderKnobs, ThemesKnobs,
    TransportKnobs, VoxelizeKnobs,
};
use super::Pipeline;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// One stage of a pipeline with its knobs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Stage {
    /// Simplify the scene into voxel patches (`crate::radiosity::patches::voxelize`).
    Voxelize(VoxelizeKnobs),
    /// Form factors between patches with BVH visibility (`crate::radiosity::formfactor`).
    FormFactors(FormFactorsKnobs),
    /// k-bounce or infinite-bounce transport matrix (`crate::radiosity::transport`).
    Transport(TransportKnobs),
    /// Greedy reordering of the transport matrix (src/compress/reorder.rs).
    Reorder(ReorderKnobs),
    /// Split, log map and block-compress the transport (src/compress/).
    Encode(EncodeKnobs),
    /// Min/max mipmap of a height map (`minmax_mipmap.exr`).
    MinmaxMipmap(MinmaxMipmapKnobs),
    /// Horizon maps of a height map (`horizon_maps.npy`, `horizon_directions.npy`).
    HorizonMaps(HorizonMapsKnobs),
    /// Thematic textures of a height map from a theme set (`themes.bin`; docs/themes.md).
    Themes(ThemesKnobs),
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
    HorizonMaps,
    Themes,
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
            Stage::HorizonMaps(_) => StageKind::HorizonMaps,
            Stage::Themes(_) => StageKind::Themes,
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
            StageKind::HorizonMaps => "horizon_maps",
            StageKind::Themes => "themes",
        }
    }

    /// The input kind the stage works on (`"scene"` or `"heightmap"`).
    pub fn input_kind(self) -> &'static str {
        match self {
            StageKind::Voxelize | StageKind::FormFactors | StageKind::Transport => "scene",
            StageKind::Reorder | StageKind::Encode => "scene",
            StageKind::MinmaxMipmap | StageKind::HorizonMaps | StageKind::Themes => "heightmap",
        }
    }

    /// Stages that must have run before this one (in this pipeline or an earlier bake).
    pub fn requires(self) -> &'static [StageKind] {
        match self {
            StageKind::Voxelize => &[],
            StageKind::FormFactors => &[StageKind::Voxelize],
            StageKind::Transport => &[StageKind::Voxelize, StageKind::FormFactors],
            StageKind::Reorder | StageKind::Encode => &[StageKind::Transport],
            StageKind::MinmaxMipmap | StageKind::HorizonMaps | StageKind::Themes => &[],
        }
    }
}

/// Check that every stage fits the input kind and comes after the stages it needs.
pub fn check_order(path: &Path, pipeline: &Pipeline) -> Result<()> {
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
