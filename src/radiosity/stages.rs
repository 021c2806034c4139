//! Pipeline glue of the radiosity stages: knobs (validated while parsing, so errors carry the
//! knob's line and column), and `StageRun` implementations that read inputs from the workspace,
//! call the pure entry functions and write the files.

use super::formfactor::{form_factors, Estimator, FormFactorParams};
use super::patches::{voxelize, Resolution, VoxelizeParams};
use super::transport::{memory_estimate, transport, Bounces, Power, TransportParams};
use super::{PatchSet, FORM_FACTORS_FILE, PATCHES_FILE, TRANSPORT_FILE};
use crate::baked::{self, BakeTransaction, StageRecord};
use crate::error::{Error, Result};
use crate::pipeline::{PlanState, PlannedStage, StageRun};
use crate::progress::Progress;
use crate::workspace::Workspace;
use serde::{Deserialize, Deserializer, Serialize};

/// Knobs of `Voxelize(...)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VoxelizeKnobs {
    /// `TargetPatches(n)` (the stage picks the voxel size) or `VoxelSize(s)` in scene units.
    #[serde(default = "default_resolution", deserialize_with = "resolution")]
    pub resolution: Resolution,
    /// Points per patch stored for the runtime's direct light.
    #[serde(
        default = "default_samples_per_patch",
        deserialize_with = "crate::pipeline::parse::at_least_one"
    )]
    pub samples_per_patch: u32,
}

/// Knobs of `FormFactors(...)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FormFactorsKnobs {
    /// `Hemisphere` (default) or `Pairwise`.
    #[serde(default)]
    pub estimator: Estimator,
    /// Rays per patch (hemisphere, default 4096) or point pairs per patch pair (pairwise,
    /// default 16).
    #[serde(
        default,
        deserialize_with = "optional_at_least_one",
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
    #[serde(default = "default_bounces", deserialize_with = "bounces")]
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
            estimator: Estimator::Hemisphere,
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

fn resolution<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Resolution, D::Error> {
    let v = Resolution::deserialize(d)?;
    match v {
        Resolution::VoxelSize(s) if !(s.is_finite() && s > 0.0) => Err(serde::de::Error::custom(
            format!("out of range: VoxelSize({s}) (must be a positive finite number)"),
        )),
        Resolution::TargetPatches(0) => Err(serde::de::Error::custom(
            "out of range: TargetPatches(0) (must be at least 1)",
        )),
        v => Ok(v),
    }
}

fn bounces<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Bounces, D::Error> {
    let v = Bounces::deserialize(d)?;
    match v {
        Bounces::Finite(0) => Err(serde::de::Error::custom(
            "out of range: Finite(0) (at least one bounce; Infinite for all)",
        )),
        Bounces::Auto(t) if !(t.is_finite() && t > 0.0) => Err(serde::de::Error::custom(format!(
            "out of range: Auto({t}) (the tolerance must be a positive finite number)"
        ))),
        v => Ok(v),
    }
}

fn optional_at_least_one<'de, D: Deserializer<'de>>(
    d: D,
) -> std::result::Result<Option<u32>, D::Error> {
    let v = Option::<u32>::deserialize(d)?;
    if v == Some(0) {
        return Err(serde::de::Error::custom(
            "out of range: 0 (must be at least 1)",
        ));
    }
    Ok(v)
}

/// Read `patches.bin`.
pub fn read_patches(path: &std::path::Path) -> Result<PatchSet> {
    baked::read_postcard(path)
}

/// Read `form_factors.npy` (or `transport.npy`): (shape, values).
pub type Matrix = (Vec<u64>, Vec<f32>);

fn patches_of(ws: &mut Workspace) -> Result<PatchSet> {
    Ok(ws.get(PATCHES_FILE, read_patches)?.clone())
}

impl StageRun for VoxelizeKnobs {
    fn run(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        progress: &dyn Progress,
    ) -> Result<StageRecord> {
        let scene = ws.scene()?;
        progress.begin("voxelize", 0);
        let set = voxelize(
            scene,
            &VoxelizeParams {
                resolution: self.resolution,
                samples_per_patch: self.samples_per_patch,
            },
        )?;
        progress.finish();
        let s = &set.stats;
        if s.degenerate_triangles > 0 {
            progress.warn(&format!(
                "voxelize: skipped {} degenerate (zero-area) triangle(s)",
                s.degenerate_triangles
            ));
        }
        if s.corners_without_patch > 0 {
            progress.warn(&format!(
                "voxelize: {} triangle corner(s) found no patch and will get no indirect light",
                s.corners_without_patch
            ));
        }
        txn.write(PATCHES_FILE, &baked::to_postcard(&set)?)?;
        let mut rec = StageRecord {
            stage: "voxelize".into(),
            outputs: vec![PATCHES_FILE.into()],
            ..Default::default()
        };
        let total_area: f64 = set.patches.iter().map(|p| p.area as f64).sum();
        for (k, v) in [
            ("patches", set.len() as f64),
            ("pieces", set.pieces.len() as f64),
            ("voxel_size", set.voxel_size),
            ("grid_x", set.dims[0] as f64),
            ("grid_y", set.dims[1] as f64),
            ("grid_z", set.dims[2] as f64),
            ("patch_area_total", total_area),
            (
                "degenerate_triangles_skipped",
                s.degenerate_triangles as f64,
            ),
            ("coplanar_covered_faces", s.covered_faces as f64),
            ("coplanar_covered_area", s.covered_area),
            ("corners_without_patch", s.corners_without_patch as f64),
            ("samples_per_patch", set.samples_per_patch as f64),
        ] {
            rec.report.insert(k.into(), v);
        }
        rec.facts.insert("grey".into(), set.is_grey().to_string());
        rec.facts.insert(
            "units".into(),
            "scene units (after the input's scale)".into(),
        );
        ws.put(PATCHES_FILE, set);
        Ok(rec)
    }

    fn estimate(&self, state: &mut PlanState) -> PlannedStage {
        let (patches, note) = match self.resolution {
            Resolution::TargetPatches(n) => (n as u64, format!("about {n} patches")),
            Resolution::VoxelSize(s) => (
                state.triangles.max(1000),
                format!(
                    "voxel size {s}: patch count known after voxelizing (assumed {})",
                    state.triangles.max(1000)
                ),
            ),
        };
        state.patches = patches;
        let output = patches * (200 + 40 * self.samples_per_patch as u64) + state.triangles * 120;
        state.resident_bytes += output;
        PlannedStage {
            stage: "voxelize".into(),
            peak_bytes: state.triangles * 2048 + output * 3,
            output_bytes: output,
            notes: note,
        }
    }
}

impl StageRun for FormFactorsKnobs {
    fn run(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        progress: &dyn Progress,
    ) -> Result<StageRecord> {
        let set = patches_of(ws)?;
        let n = set.len();
        let n2 = (n * n) as u64;
        crate::limits::check_memory(
            &format!("the form factors of {n} patches"),
            n2 * 4 * 3,
            ws.memory_budget(),
        )?;
        let samples = self
            .samples
            .unwrap_or_else(|| self.estimator.default_samples());
        let params = FormFactorParams {
            estimator: self.estimator,
            samples,
            seed: self.seed,
        };
        let f = form_factors(ws.scene()?, &set, &params, progress)?;
        txn.write_with(FORM_FACTORS_FILE, |p| {
            baked::write_npy_f32(p, &[n as u64, n as u64], &f.values)
        })?;
        let mut rec = StageRecord {
            stage: "form_factors".into(),
            outputs: vec![FORM_FACTORS_FILE.into()],
            ..Default::default()
        };
        let sums: Vec<f64> = (0..n).map(|i| f.row_sum(i)).collect();
        let mut reciprocity = (0.0, 0.0);
        for i in 0..n {
            for j in i + 1..n {
                let (a, b) = (
                    set.patches[i].area as f64 * f.get(i, j) as f64,
                    set.patches[j].area as f64 * f.get(j, i) as f64,
                );
                reciprocity.0 += (a - b).abs();
                reciprocity.1 += a + b;
            }
        }
        for (k, v) in [
            ("patches", n as f64),
            ("samples", samples as f64),
            ("rays", f.rays as f64),
            ("unassigned_hits", f.unassigned_hits as f64),
            (
                "row_sum_min",
                sums.iter().copied().fold(f64::INFINITY, f64::min),
            ),
            ("row_sum_max", sums.iter().copied().fold(0.0, f64::max)),
            ("row_sum_mean", sums.iter().sum::<f64>() / n as f64),
            (
                "reciprocity_error",
                2.0 * reciprocity.0 / reciprocity.1.max(f64::MIN_POSITIVE),
            ),
            (
                "nonzero_fraction",
                f.values.iter().filter(|&&v| v != 0.0).count() as f64 / n2 as f64,
            ),
        ] {
            rec.report.insert(k.into(), v);
        }
        rec.facts
            .insert("estimator".into(), format!("{:?}", self.estimator));
        rec.facts.insert(
            "layout".into(),
            "[n, n] f32 row-major: row i = F_ij, fraction of the energy leaving i that arrives at j".into(),
        );
        ws.put(
            FORM_FACTORS_FILE,
            (vec![n as u64, n as u64], f.values) as Matrix,
        );
        Ok(rec)
    }

    fn estimate(&self, state: &mut PlanState) -> PlannedStage {
        let n2 = state.patches * state.patches;
        state.resident_bytes += n2 * 4;
        PlannedStage {
            stage: "form_factors".into(),
            peak_bytes: n2 * 8 + state.triangles * 256,
            output_bytes: n2 * 4,
            notes: format!(
                "{:?}, {} patches: dense [n, n] f32",
                self.estimator, state.patches
            ),
        }
    }
}

impl StageRun for TransportKnobs {
    fn run(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        progress: &dyn Progress,
    ) -> Result<StageRecord> {
        let set = patches_of(ws)?;
        let albedo: Vec<[f32; 3]> = set.patches.iter().map(|p| p.albedo).collect();
        let n = set.len();
        let budget = ws.memory_budget();
        let (shape, f) = ws.get(FORM_FACTORS_FILE, baked::read_npy_f32)?;
        if shape.as_slice() != [n as u64, n as u64] {
            return Err(Error::input(
                FORM_FACTORS_FILE,
                format!("shape {shape:?} does not match the {n} patches of {PATCHES_FILE}; re-run form_factors"),
            ));
        }
        let t = transport(
            f,
            n,
            &albedo,
            &TransportParams {
                bounces: self.bounces,
                power: self.power,
                max_memory: budget,
            },
            progress,
        )?;
        txn.write_with(TRANSPORT_FILE, |p| {
            baked::write_npy_f32(p, &[t.channels as u64, n as u64, n as u64], &t.values)
        })?;
        let mut rec = StageRecord {
            stage: "transport".into(),
            outputs: vec![TRANSPORT_FILE.into()],
            ..Default::default()
        };
        rec.report.insert("channels".into(), t.channels as f64);
        rec.report.insert("patches".into(), n as f64);
        rec.report.insert("products".into(), t.products as f64);
        for (c, k) in t.bounces.iter().enumerate() {
            rec.report.insert(format!("bounces_{c}"), *k as f64);
        }
        for (c, (lo, hi)) in t.spectral_bounds.iter().enumerate() {
            rec.report.insert(format!("spectral_radius_low_{c}"), *lo);
            rec.report.insert(format!("spectral_radius_high_{c}"), *hi);
        }
        let max = t.values.iter().copied().fold(0f32, f32::max);
        rec.report.insert("max_entry".into(), max as f64);
        rec.facts.insert(
            "layout".into(),
            "[channels, n, n] f32 row-major; channels = 1 (grey: serves R, G, B) or 3 (R, G, B)"
                .into(),
        );
        rec.facts
            .insert("bounces".into(), format!("{:?}", self.bounces));
        // Later stages (reorder, encode) take the matrix as the one transport type.
        ws.put(
            TRANSPORT_FILE,
            crate::compress::TransportMatrix::new(t.channels, n, t.values)?,
        );
        Ok(rec)
    }

    fn estimate(&self, state: &mut PlanState) -> PlannedStage {
        let n = state.patches as usize;
        let channels = state.channels.max(1);
        // The form factors are already counted as resident by the plan.
        let bytes = memory_estimate(n, channels as usize, self.bounces) - (n * n) as u64 * 4;
        PlannedStage {
            stage: "transport".into(),
            peak_bytes: bytes,
            output_bytes: channels * state.patches * state.patches * 4,
            notes: format!("{:?}, {channels} channel(s)", self.bounces),
        }
    }
}
