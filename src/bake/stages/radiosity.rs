//! The radiosity stages `voxelize` and `form_factors` (whole or in shards of rows); `transport`
//! is in `transport.rs`.

use super::{record, StageRun};
use crate::bake::estimate::{PlanState, PlannedStage};
use crate::bake::workspace::Workspace;
use crate::baked::shard::{Mapped, Payload};
use crate::baked::{self, form_factors::FormFactorMatrix, BakeTransaction, StageRecord};
use crate::error::{Error, Result};
use crate::pipeline::knobs::{FormFactorsKnobs, VoxelizeKnobs};
use crate::progress::Progress;
use crate::radiosity::formfactor::{
    assemble, form_factor_rows, form_factors, shard_rows, Estimator, FormFactors, RowBlock,
};
use crate::radiosity::patches::voxelize::{voxelize_noting, Resolution};
use std::path::PathBuf;

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
        if let Some(why) = &note {
            let asked = match self.resolution {
                Resolution::TargetPatches(n) => format!("TargetPatches({n})"),
                Resolution::Adaptive(a) => format!("Adaptive(target: {})", a.target),
                Resolution::VoxelSize(s) => format!("VoxelSize({s})"),
            };
            progress.warn(&format!(
                "voxelize: {asked} gave {} patches: {why}",
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
            (None, Resolution::Adaptive(a)) => (
                a.target as u64,
                format!(
                    "assumes Adaptive(target: {}) gives {} patches; re-checked after voxelize",
                    a.target, a.target
                ),
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
        // Clipping, clustering and the visibility tree: about 1 KiB per triangle (measured peak
        // RSS: Dabrovic Sponza 0.9 KiB, the furnished room 1.2 KiB), and a material's summed-area
        // table (32 bytes per texel) while its pieces' albedo is integrated.
        PlannedStage {
            stage: "voxelize".into(),
            peak_bytes: state.triangles * 1024 + state.largest_texture_texels * 32 + output * 3,
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
        check_form_factor_memory(set.len(), budget)?;
        let f = form_factors(scene, set, &self.params(), progress)?;
        self.finish(ws, txn, f)
    }

    fn shardable(&self) -> bool {
        true
    }

    fn run_shard(
        &self,
        ws: &mut Workspace,
        index: usize,
        count: usize,
        _prepared: Option<Mapped>,
        progress: &dyn Progress,
    ) -> Result<(String, Payload)> {
        let (scene, set) = ws.scene_and_patches()?;
        let n = set.len();
        let rows = shard_rows(self.estimator, n, index, count);
        let block = form_factor_rows(scene, set, &self.params(), rows.clone(), progress)?;
        let mut p = Payload::default();
        p.u64s
            .insert("rows".into(), vec![rows.start as u64, rows.end as u64]);
        match block {
            RowBlock::Hemisphere {
                values, unassigned, ..
            } => {
                p.f32s.insert("values".into(), values);
                p.u64s.insert("unassigned".into(), vec![unassigned]);
            }
            RowBlock::Pairwise { upper, .. } => {
                p.f64s.insert("upper".into(), upper);
            }
        }
        Ok((format!("rows {}..{} of {n}", rows.start, rows.end), p))
    }

    fn merge_shards(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        shards: Vec<PathBuf>,
        _prepared: Option<Mapped>,
    ) -> Result<StageRecord> {
        let budget = ws.memory_budget();
        let set = ws.patches()?;
        let n = set.len();
        check_form_factor_memory(n, budget)?;
        let count = shards.len();
        // One block of all rows, filled shard by shard (one shard's arrays held at a time).
        let (mut values, mut upper, mut unassigned) = (Vec::new(), Vec::new(), 0);
        for (i, path) in shards.into_iter().enumerate() {
            let (_, mut p) = crate::baked::shard::read(&path)?;
            let want = shard_rows(self.estimator, n, i, count);
            let rows = p.u64s("rows", &path)?;
            if rows != [want.start as u64, want.end as u64] {
                return Err(Error::verify(
                    &path,
                    format!("holds rows {rows:?}, shard {i} of {count} should hold {want:?}"),
                ));
            }
            let len_ok = if self.estimator == Estimator::Pairwise {
                let u = p.f64s("upper", &path)?;
                let ok = u.len() == want.clone().map(|r| n - r).sum::<usize>();
                upper.extend(u);
                ok
            } else {
                let v = p.f32s("values", &path)?;
                let ok = v.len() == want.len() * n;
                values.extend(v);
                unassigned += p.u64s("unassigned", &path)?.first().copied().unwrap_or(0);
                ok
            };
            if !len_ok {
                return Err(Error::verify(
                    &path,
                    "its rows do not have the patches' length",
                ));
            }
        }
        let block = if self.estimator == Estimator::Pairwise {
            RowBlock::Pairwise { rows: 0..n, upper }
        } else {
            RowBlock::Hemisphere {
                rows: 0..n,
                values,
                unassigned,
            }
        };
        let f = assemble(set, &self.params(), std::slice::from_ref(&block))?;
        drop(block);
        self.finish(ws, txn, f)
    }

    fn estimate_shard(&self, state: &PlanState, index: usize, count: usize) -> u64 {
        let n = state.patches as usize;
        let rows = shard_rows(self.estimator, n, index, count).len() as u64;
        // Hemisphere rows in f32; pairwise upper rows in f64, at most n entries each.
        let per_row = state.patches
            * if self.estimator == Estimator::Pairwise {
                8
            } else {
                4
            };
        state.triangles * 256 + rows * per_row
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

fn check_form_factor_memory(n: usize, budget: u64) -> Result<()> {
    crate::limits::check_memory(
        &format!("the form factors of {n} patches"),
        (n * n) as u64 * 4 * 3,
        budget,
    )
}

impl FormFactorsKnobs {
    /// Write F and build the stage's record (shared by `run` and the merge of shards).
    fn finish(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        f: FormFactors,
    ) -> Result<StageRecord> {
        let set = ws.patches()?;
        let n = f.n;
        let n2 = (n * n) as u64;
        let samples = self.samples();
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
}
