//! Pipeline files (RON): what to bake, with which knobs, into which directory. A [`Pipeline`] is
//! the one settings value that drives every stage (gltfpack's `Settings`): parsing turns a file
//! into a validated plan before any work starts (ripgrep's args → plan), and the manifest of the
//! bake records the resolved pipeline so a bake can be reproduced.
//!
//! ```ron
//! Pipeline(
//!     input: Scene(path: "../scenes/cornell-box/cornell_box.obj", scale: 0.001),
//!     output: "out/cornell",
//!     stages: [ /* one entry per stage, in order */ ],
//! )
//! ```
//! Input paths are relative to the pipeline file; the output directory is relative to the
//! current directory (and `--out` overrides it).

pub mod checks;
pub mod knobs;
pub mod parse;
mod stage;

pub use parse::{parse_pipeline, PLANNED_STAGES};
pub use stage::{check_order, Stage, StageKind};

use crate::heightmap::{HeightMapOptions, NoDataPolicy};
use crate::scene::SceneOptions;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A whole bake description.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pipeline {
    /// What the bake reads.
    pub input: Input,
    /// Where the baked directory goes (relative to the current directory). Default
    /// `out/<pipeline file stem>`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output: Option<PathBuf>,
    /// The stages, in order.
    #[serde(default)]
    pub stages: Vec<Stage>,
}

/// The input of a bake: a mesh scene or a height map.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Input {
    /// An OBJ (+MTL), glTF or GLB scene.
    Scene(SceneInput),
    /// A height map (PNG, JPEG, EXR, GeoTIFF or raw f32).
    HeightMap(HeightMapInput),
}

/// Knobs of a scene input.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneInput {
    /// Path of the scene file, relative to the pipeline file.
    pub path: PathBuf,
    /// Factor applied to all positions (0.001 turns millimetres into metres). Default 1.
    #[serde(default = "one", deserialize_with = "checks::de::positive_f32")]
    pub scale: f32,
    /// Punctual lights added to the scene's own, in world units (after `scale`); the player
    /// lights the scene with them every frame (the baked transport does not depend on them).
    #[serde(
        default,
        deserialize_with = "checks::de::lights",
        skip_serializing_if = "Vec::is_empty"
    )]
    pub lights: Vec<crate::scene::punctual::LightSpec>,
}

/// Knobs of a height-map input.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeightMapInput {
    /// Path of the height map, relative to the pipeline file.
    pub path: PathBuf,
    /// Metres per texel (x, y); default: the GeoTIFF world file or pixel-scale tag, else 1 m.
    #[serde(
        default,
        deserialize_with = "checks::de::optional_cell_size",
        skip_serializing_if = "Option::is_none"
    )]
    pub cell_size: Option<(f64, f64)>,
    /// Metres per file unit (default 1).
    #[serde(
        default,
        deserialize_with = "checks::de::optional_positive_f64",
        skip_serializing_if = "Option::is_none"
    )]
    pub height_scale: Option<f64>,
    /// Value marking missing data, in file units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nodata_value: Option<f64>,
    /// Policy for no-data texels: `Error` (default), `FillMin`, `FillNearest`.
    #[serde(default)]
    pub nodata: NoDataPolicy,
    /// (width, height) of a raw f32 file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub raw_size: Option<(usize, usize)>,
    /// Box-filter the map down by this integer factor after loading (2: 4096² → 2048²); the
    /// cell size grows by the same factor. Default 1.
    #[serde(
        default = "one_u32",
        deserialize_with = "checks::de::at_least_one",
        skip_serializing_if = "is_one"
    )]
    pub downsample: u32,
}

fn one_u32() -> u32 {
    1
}

fn is_one(v: &u32) -> bool {
    *v == 1
}

fn one() -> f32 {
    1.0
}

/// Where a bake of the pipeline at `pipeline_path` goes: `out` (the `--out` flag), else the
/// pipeline's `output`, else `out/<pipeline file stem>`.
pub fn output_dir(pipeline_path: &Path, p: &Pipeline, out: Option<&Path>) -> PathBuf {
    if let Some(o) = out {
        return o.to_path_buf();
    }
    if let Some(o) = &p.output {
        return o.clone();
    }
    let stem = pipeline_path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "bake".into());
    PathBuf::from("out").join(stem)
}

impl SceneInput {
    /// Loader options of this input.
    pub fn options(&self) -> SceneOptions {
        SceneOptions { scale: self.scale }
    }
}

impl HeightMapInput {
    /// Loader options of this input.
    pub fn options(&self) -> HeightMapOptions {
        HeightMapOptions {
            cell_size: self.cell_size.map(|(x, y)| [x, y]),
            height_scale: self.height_scale,
            nodata_value: self.nodata_value,
            nodata: self.nodata,
            raw_size: self.raw_size.map(|(w, h)| [w, h]),
            downsample: self.downsample,
        }
    }
}

impl Input {
    /// The input file path as written in the pipeline.
    pub fn path(&self) -> &Path {
        match self {
            Input::Scene(s) => &s.path,
            Input::HeightMap(h) => &h.path,
        }
    }

    /// Resolve the input path against the pipeline file's directory.
    pub fn resolve(&mut self, base: &Path) {
        let p = match self {
            Input::Scene(s) => &mut s.path,
            Input::HeightMap(h) => &mut h.path,
        };
        if p.is_relative() {
            *p = base.join(&*p);
        }
    }

    /// `"scene"` or `"heightmap"`.
    pub fn kind(&self) -> &'static str {
        match self {
            Input::Scene(_) => "scene",
            Input::HeightMap(_) => "heightmap",
        }
    }
}
