//! The radiosity stages: `voxelize`, `form_factors`, `transport`.

use super::{record, StageRun};
use crate::bake::estimate::{PlanState, PlannedStage};
use crate::bake::workspace::Workspace;
use crate::baked::{self, form_factors::FormFactorMatrix, BakeTransaction, StageRecord};
use crate::error::{Error, Result};
use crate::pipeline::knobs::{FormFactorsKnobs, TransportKnobs, VoxelizeKnobs};
use crate::progress::Progress;
use crate::radiosity::formfactor::form_factors;
use crate::radiosity::transport::{memory_estimate, transport, TransportParams};
use crate::radiosity::voxelize::{voxelize_noting, Resolution};

impl StageRun for VoxelizeKnobs {
    fn run(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        progress: &dyn Progress,
    ) -> Result<StageRecord> {
        let scene = ws.scene()?;
        progress.begin("voxelize", 0);
        let (set, note) = voxelize_noting(scene, &self.params())?;
        progress.finish();
        if let (Resolution::TargetPatches(n), Some(why)) = (self.resolution, &note) {
            progress.warn(&format!(
                "voxelize: TargetPatches({n}) gave {} patches: {why}",
                set.len()
            ));
        }
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
        baked::patches::write(txn, &set)?;
        let mut rec = record("voxelize", &[baked::patches::FILE]);
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
        if let Some(why) = note {
            rec.facts.insert("target_missed".into(), why);
        }
        rec.facts.insert(
            "units".into(),
            "scene units (after the input's scale)".into(),
        );
        ws.set_patches(set);
        Ok(rec)
    }

    fn estimate(&self, state: &mut PlanState) -> PlannedStage {
        let (patches, note) = match (state.measured_patches, self.resolution) {
            (Some(p), _) => (p, format!("{p} patches (measured)")),
            (None, Resolution::TargetPatches(n)) => (
                n as u64,
                format!("assumes TargetPatches({n}) gives {n} patches; re-checked after voxelize"),
            ),
            (None, Resolution::VoxelSize(s)) => (
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
        let budget = ws.memory_budget();
        let (scene, set) = ws.scene_and_patches()?;
        let n = set.len();
        let n2 = (n * n) as u64;
        crate::limits::check_memory(
            &format!("the form factors of {n} patches"),
            n2 * 4 * 3,
            budget,
        )?;
        let samples = self.samples();
        let f = form_factors(scene, set, &self.params(), progress)?;
        let sums: Vec<f64> = (0..n).map(|i| f.row_sum(i)).collect();
        let matrix = FormFactorMatrix {
            n,
            values: f.values,
        };
        baked::form_factors::write(txn, &matrix)?;
        let mut rec = record("form_factors", &[baked::form_factors::FILE]);
        let mut reciprocity = (0.0, 0.0);
        for i in 0..n {
            for j in i + 1..n {
                let (a, b) = (
                    set.patches[i].area as f64 * matrix.values[i * n + j] as f64,
                    set.patches[j].area as f64 * matrix.values[j * n + i] as f64,
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
                matrix.values.iter().filter(|&&v| v != 0.0).count() as f64 / n2 as f64,
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
        ws.set_form_factors(matrix);
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
        let set = ws.patches()?;
        let albedo: Vec<[f32; 3]> = set.patches.iter().map(|p| p.albedo).collect();
        let n = set.len();
        let budget = ws.memory_budget();
        let f = ws.form_factors()?;
        if f.n != n {
            return Err(Error::input(
                baked::form_factors::FILE,
                format!(
                    "shape {:?} does not match the {n} patches of {}; re-run form_factors",
                    [f.n, f.n],
                    baked::patches::FILE
                ),
            ));
        }
        let t = transport(
            &f.values,
            n,
            &albedo,
            &TransportParams {
                bounces: self.bounces,
                power: self.power,
                max_memory: budget,
                solver: Default::default(),
            },
            progress,
        )?;
        baked::transport::write(txn, &t.matrix)?;
        let mut rec = record("transport", &[baked::transport::FILE]);
        rec.report
            .insert("channels".into(), t.matrix.channels as f64);
        rec.report.insert("patches".into(), n as f64);
        rec.report.insert("products".into(), t.products as f64);
        for (c, k) in t.bounces.iter().enumerate() {
            rec.report.insert(format!("bounces_{c}"), *k as f64);
        }
        for (c, (lo, hi)) in t.spectral_bounds.iter().enumerate() {
            rec.report.insert(format!("spectral_radius_low_{c}"), *lo);
            rec.report.insert(format!("spectral_radius_high_{c}"), *hi);
        }
        for (c, (solver, err)) in t.solvers.iter().enumerate() {
            rec.facts
                .insert(format!("solver_{c}"), format!("{solver:?} LU"));
            rec.report
                .insert(format!("solver_error_estimate_{c}"), *err);
        }
        let max = t.matrix.data.iter().copied().fold(0f32, f32::max);
        rec.report.insert("max_entry".into(), max as f64);
        rec.facts.insert(
            "layout".into(),
            "[channels, n, n] f32 row-major; channels = 1 (grey: serves R, G, B) or 3 (R, G, B)"
                .into(),
        );
        rec.facts
            .insert("bounces".into(), format!("{:?}", self.bounces));
        ws.set_transport(t.matrix);
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
