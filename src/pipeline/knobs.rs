//! Every stage's knobs, with their defaults and range checks ([`super::checks`]): the plain
//! description a pipeline file parses into, and the values command-line flags fall back to
//! (flags are `Option`s; `None` means the default below). Each knob struct converts into the
//! parameters of its algorithm, which knows nothing of pipelines.

use super::checks;
use crate::compress::containers::Container;
use crate::compress::dense::{DenseEncoding, EncodeOptions};
use crate::compress::reorder::{ReorderMethod, ReorderMetric, ReorderOptions};
use crate::radiosity::formfactor::{Estimator, FormFactorParams};
use crate::radiosity::patches::voxelize::{Resolution, VoxelizeParams};
use crate::radiosity::transport::{Bounces, Power};
use crate::terrain::horizon::map::HorizonSettings;
use serde::{Deserialize, Serialize};

/// Knobs of `Voxelize(...)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VoxelizeKnobs {
    /// `TargetPatches(n)` (the stage picks the voxel size), `VoxelSize(s)` in scene units, or
    /// `Adaptive(target: n, ..)` (refined where materials, geometry or light vary).
    #[serde(
        default = "default_resolution",
        deserialize_with = "checks::de::resolution"
    )]
    pub resolution: Resolution,
    /// Points per patch stored for the runtime's direct light.
    #[serde(
        default = "default_samples_per_patch",
        deserialize_with = "checks::de::at_least_one"
    )]
    pub samples_per_patch: u32,
}

/// Knobs of `FormFactors(...)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FormFactorsKnobs {
    /// `HemisphereReciprocal` (default), `Hemisphere` or `Pairwise`.
    #[serde(default)]
    pub estimator: Estimator,
    /// Rays per patch (hemisphere, default 4096) or point pairs per patch pair (pairwise,
    /// default 16).
    #[serde(
        default,
        deserialize_with = "checks::de::optional_at_least_one",
        skip_serializing_if = "Option::is_none"
    )]
    pub samples: Option<u32>,
    /// Seed of the random numbers (the output is a pure function of it).
    #[serde(default)]
    pub seed: u64,
}

/// Knobs of `Transport(...)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransportKnobs {
    /// `Finite(k)` (k ≥ 1), `Infinite` (default) or `Auto(tolerance)`.
    #[serde(default = "default_bounces", deserialize_with = "checks::de::bounces")]
    pub bounces: Bounces,
    /// `Auto` (default), `Horner` or `Doubling`: how finite k is evaluated.
    #[serde(default)]
    pub power: Power,
}

impl Default for VoxelizeKnobs {
    fn default() -> Self {
        VoxelizeKnobs {
            resolution: default_resolution(),
            samples_per_patch: default_samples_per_patch(),
        }
    }
}

impl Default for FormFactorsKnobs {
    fn default() -> Self {
        FormFactorsKnobs {
            estimator: Estimator::HemisphereReciprocal,
            samples: None,
            seed: 0,
        }
    }
}

impl Default for TransportKnobs {
    fn default() -> Self {
        TransportKnobs {
            bounces: default_bounces(),
            power: Power::Auto,
        }
    }
}

fn default_resolution() -> Resolution {
    Resolution::TargetPatches(1000)
}

fn default_samples_per_patch() -> u32 {
    4
}

fn default_bounces() -> Bounces {
    Bounces::Infinite
}

/// Knobs of the `reorder` stage.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReorderKnobs {
    /// Greedy passes: 0 (identity), 1 (rows), 2 (rows then columns, the radiosity thesis's).
    #[serde(
        default = "default_passes",
        deserialize_with = "checks::de::reorder_passes"
    )]
    pub passes: u8,
    /// `Linear` (the radiosity thesis's: raw values, default) or `Log` (the 8-bit log codes the encoder
    /// sees; measured no better, see docs/compression.md).
    #[serde(default = "default_metric")]
    pub metric: ReorderMetric,
    /// `Budgeted` (default: the greedy walk with lower bounds and at most 8 exact distances per
    /// step), `Bounded` (the thesis's exact greedy order, found with lower bounds) or `Full`
    /// (the thesis's all-pairs distance matrix, O(n³); the same order as `Bounded`).
    #[serde(default)]
    pub method: ReorderMethod,
}

fn default_passes() -> u8 {
    2
}
fn default_metric() -> ReorderMetric {
    ReorderMetric::Linear
}

impl Default for ReorderKnobs {
    fn default() -> Self {
        ReorderKnobs {
            passes: default_passes(),
            metric: default_metric(),
            method: ReorderMethod::default(),
        }
    }
}

/// Knobs of the `encode` stage.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EncodeKnobs {
    /// Dense-part encoding: `Bc6h` (default), `Bc1Log` (the radiosity thesis's), `Bc4Log`, `F16`, `F32`.
    #[serde(default = "default_encoding")]
    pub encoding: DenseEncoding,
    /// Percentage of the entries (largest first) kept exactly in the sidecar.
    #[serde(default = "default_split", deserialize_with = "checks::de::percent")]
    pub split_percent: f64,
    /// Natural-log range of the log mapping (the radiosity thesis's 25).
    #[serde(
        default = "default_log_range",
        deserialize_with = "checks::de::positive_f32"
    )]
    pub log_range: f32,
    /// Carry each row's running error into the next block (keeps row sums).
    #[serde(default = "default_feedback")]
    pub feedback: bool,
    /// Fill the sidecar's holes in the dense part instead of zeroing them (sidecar holds the
    /// residual).
    #[serde(default = "default_fill_holes")]
    pub fill_holes: bool,
    /// Largest texture side; bigger matrices are split into tiles.
    #[serde(
        default = "default_max_texture_size",
        deserialize_with = "checks::de::texture_size"
    )]
    pub max_texture_size: u32,
    /// Containers to write (at least one).
    #[serde(default = "default_containers")]
    pub containers: Vec<Container>,
}

/// The default encoding: BC6H with filled holes and a 1 % sidecar reached the goal
/// (≤ 2 % RMS relative gather error at ≤ 1.5x the bytes of the radiosity thesis's scheme) by a wide margin; see
/// docs/compression.md for the measurements.
fn default_encoding() -> DenseEncoding {
    DenseEncoding::Bc6h
}
fn default_split() -> f64 {
    1.0
}
fn default_log_range() -> f32 {
    crate::compress::logmap::SEED_RANGE
}
fn default_feedback() -> bool {
    false
}
fn default_fill_holes() -> bool {
    true
}
fn default_max_texture_size() -> u32 {
    8192
}
fn default_containers() -> Vec<Container> {
    vec![Container::Dds, Container::Ktx2]
}

impl Default for EncodeKnobs {
    fn default() -> Self {
        EncodeKnobs {
            encoding: default_encoding(),
            split_percent: default_split(),
            log_range: default_log_range(),
            feedback: default_feedback(),
            fill_holes: default_fill_holes(),
            max_texture_size: default_max_texture_size(),
            containers: default_containers(),
        }
    }
}

impl EncodeKnobs {
    /// The dense-encoding options of these knobs.
    pub fn options(&self) -> EncodeOptions {
        EncodeOptions {
            encoding: self.encoding,
            log_range: self.log_range,
            feedback: self.feedback,
            fill_holes: self.fill_holes,
        }
    }
}

/// Knobs of the `minmax_mipmap` stage (none yet: `MinmaxMipmap()` in a pipeline).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MinmaxMipmapKnobs {}

/// Knobs of `HorizonMaps(...)`: horizon angles toward N azimuths at every texel
/// (`horizon_maps.npy`), for shadows of any sun in O(1) per pixel and the sky-view factor.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HorizonMapsKnobs {
    /// Azimuths (near-uniform rational directions), 1..=360; default 64. The file holds
    /// 2·N bytes per texel.
    #[serde(
        default = "default_horizon_directions",
        deserialize_with = "checks::de::horizon_directions"
    )]
    pub directions: u32,
    /// Planet radius in metres for curved ground (Earth: 6371000); absent: flat ground.
    #[serde(
        default,
        deserialize_with = "checks::de::optional_positive_f64",
        skip_serializing_if = "Option::is_none"
    )]
    pub planet_radius: Option<f64>,
}

/// Knobs of `Themes(file: "THEMES.ron")`: the theme set (docs/themes.md) whose index map,
/// textures and turbulence the bake stores (`themes.bin`). The path is relative to the
/// pipeline file; a `Rules` map that names no height map uses the pipeline's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThemesKnobs {
    pub file: std::path::PathBuf,
}

/// The default number of horizon azimuths.
pub const DEFAULT_HORIZON_DIRECTIONS: u32 = 64;

/// Shaded relief (`shadow --shaded`): the shadow brightness with the sun on the horizon and at
/// the zenith, k_dark and k_bright of the relief-shadow paper's eq. 4 (docs/algorithms.md §4).
pub const DEFAULT_K_DARK: f64 = 0.2;
pub const DEFAULT_K_BRIGHT: f64 = 0.6;

/// Soft shadows (`softshadow`): samples along the track of the uniform method.
pub const DEFAULT_SOFT_STEPS: u32 = 100;
/// Soft shadows: the mipmap level the dynamic programme starts from (−1 = texels).
pub const DEFAULT_SOFT_START_LEVEL: i32 = 4;
/// Soft shadows: the dynamic programme's intervals along the track (0 = as many as it needs).
pub const DEFAULT_SOFT_INTERVALS: u32 = 0;

fn default_horizon_directions() -> u32 {
    DEFAULT_HORIZON_DIRECTIONS
}

impl Default for HorizonMapsKnobs {
    fn default() -> Self {
        HorizonMapsKnobs {
            directions: DEFAULT_HORIZON_DIRECTIONS,
            planet_radius: None,
        }
    }
}

impl HorizonMapsKnobs {
    /// The settings of [`crate::terrain::horizon::map::HorizonMap::build`].
    pub fn settings(&self) -> HorizonSettings {
        HorizonSettings {
            directions: self.directions as usize,
            planet_radius: self.planet_radius,
        }
    }
}

impl VoxelizeKnobs {
    /// The parameters of [`crate::radiosity::patches::voxelize::voxelize`].
    pub fn params(&self) -> VoxelizeParams {
        VoxelizeParams {
            resolution: self.resolution,
            samples_per_patch: self.samples_per_patch,
        }
    }
}

impl FormFactorsKnobs {
    /// Samples per patch (or per patch pair): the knob, else the estimator's default.
    pub fn samples(&self) -> u32 {
        self.samples
            .unwrap_or_else(|| self.estimator.default_samples())
    }

    /// The parameters of [`crate::radiosity::formfactor::form_factors`].
    pub fn params(&self) -> FormFactorParams {
        FormFactorParams {
            estimator: self.estimator,
            samples: self.samples(),
            seed: self.seed,
        }
    }
}

impl ReorderKnobs {
    /// The options of [`crate::compress::reorder::reorder`].
    pub fn options(&self) -> ReorderOptions {
        ReorderOptions {
            passes: self.passes,
            metric: self.metric,
            method: self.method,
        }
    }
}
