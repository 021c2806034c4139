//! The compression stages: `reorder` and `encode`.

use super::{record, StageRun};
use crate::bake::estimate::{PlanState, PlannedStage};
use crate::bake::workspace::Workspace;
use crate::baked::{self, BakeTransaction, StageRecord};
use crate::compress::compress;
use crate::compress::dense::DenseEncoding;
use crate::compress::reorder::{reorder, ReorderMethod, ReorderMetric};
use crate::compress::reorder_bounded::permute_symmetric_in_place;
use crate::compress::reorder_bounded::{COARSE, FINE};
use crate::compress::report::{report_from, standard_lights};
use crate::error::{Error, Result};
use crate::pipeline::knobs::{EncodeKnobs, ReorderKnobs};
use crate::progress::Progress;

impl StageRun for ReorderKnobs {
    fn run(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        progress: &dyn Progress,
    ) -> Result<StageRecord> {
        let s = ws.transport_mut()?;
        progress.begin("reorder", 0);
        let perm = reorder(s, self.options());
        progress.finish();
        let moved = perm
            .iter()
            .enumerate()
            .filter(|(k, &p)| *k != p as usize)
            .count();
        baked::permutation::write(txn, &perm)?;
        let mut rec = record("reorder", &[baked::permutation::FILE]);
        rec.report.insert("patches".into(), perm.len() as f64);
        rec.report.insert("moved".into(), moved as f64);
        rec.facts
            .insert("metric".into(), format!("{:?}", self.metric));
        ws.set_permutation(perm);
        Ok(rec)
    }

    fn estimate(&self, state: &mut PlanState) -> PlannedStage {
        let n = state.patches;
        let ch = state.channels.max(1);
        // The bounded walks (linear metric) permute and transpose S in place and keep per row
        // 512 f64 and 32 f32 group sums per channel; the full one (and any walk with the log
        // metric) feature vectors, the distance matrix and a permuted copy.
        let in_place = self.metric == ReorderMetric::Linear && self.method != ReorderMethod::Full;
        let peak_bytes = if in_place {
            4 * n * n * ch + (8 * FINE as u64 + 4 * COARSE as u64) * n * ch
        } else {
            4 * n * n * (2 * ch + 1)
        };
        PlannedStage {
            stage: "reorder".into(),
            peak_bytes,
            output_bytes: 12 + 4 * n,
            notes: format!("{} greedy pass(es) over {n} patches", self.passes),
        }
    }
}

impl StageRun for EncodeKnobs {
    fn run(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        progress: &dyn Progress,
    ) -> Result<StageRecord> {
        if self.containers.is_empty() {
            return Err(Error::knob(
                "`containers` must name at least one of Dds, Ktx2",
            ));
        }
        let perm = if ws.has_permutation() {
            Some(ws.permutation()?.clone())
        } else {
            None
        };
        let s = ws.transport()?;
        let perm = match perm {
            Some(p) if p.len() != s.n => {
                return Err(Error::input(
                    baked::permutation::FILE,
                    format!("has {} entries, the transport has {} patches", p.len(), s.n),
                ))
            }
            Some(p) => p,
            None => (0..s.n as u32).collect(),
        };
        // The exact gathers of the report first; then S is permuted in place (P S Pᵀ, no
        // copy), encoded, and restored bit for bit whatever the outcome.
        let lights = standard_lights(s.channels, s.n);
        let exact: Vec<Vec<f32>> = lights.iter().map(|(_, e)| s.mat_vec(e)).collect();
        let moved = perm.iter().enumerate().any(|(k, &p)| p as usize != k);
        let s = ws.transport_mut()?;
        progress.begin("encode", 0);
        if moved {
            permute_symmetric_in_place(s, &perm, false);
        }
        let encoded = compress(s, perm.clone(), self.split_percent, &self.options());
        progress.finish();
        let reported = encoded.map(|enc| {
            progress.begin("encode report", 0);
            let rep = report_from(&exact, s, &enc, &lights);
            progress.finish();
            (enc, rep)
        });
        if moved {
            permute_symmetric_in_place(s, &perm, true);
        }
        let (enc, rep) = reported?;
        let (outputs, tiles) =
            baked::encoded::write(txn, &enc, self.max_texture_size as usize, &self.containers)?;
        let mut rec = StageRecord {
            stage: "encode".into(),
            outputs,
            report: rep.to_map(),
            ..Default::default()
        };
        rec.report.insert("tiles".into(), tiles.len() as f64);
        rec.report
            .insert("padded_size".into(), enc.dense.padded as f64);
        rec.facts
            .insert("encoding".into(), enc.dense.encoding.name().into());
        rec.facts.insert(
            "tiles".into(),
            tiles
                .iter()
                .map(|t| {
                    format!(
                        "{} rows {}+{} cols {}+{}",
                        t.stem, t.row0, t.rows, t.col0, t.cols
                    )
                })
                .collect::<Vec<_>>()
                .join("; "),
        );
        rec.facts.insert(
            "gather_error".into(),
            "RMS relative error of S·E for the standard lights (uniform, random, half, one)".into(),
        );
        ws.set_encoded(enc);
        Ok(rec)
    }

    fn estimate(&self, state: &mut PlanState) -> PlannedStage {
        let n = state.patches;
        let ch = state.channels.max(1);
        let padded = 4 * n.div_ceil(4);
        let per_entry = match self.encoding {
            DenseEncoding::Bc1Log => 0.5,
            DenseEncoding::Bc4Log => 0.5 * ch as f64,
            DenseEncoding::Bc6h => 1.0,
            DenseEncoding::F16 => 2.0 * ch as f64,
            DenseEncoding::F32 => 4.0 * ch as f64,
        };
        let dense = (padded * padded) as f64 * per_entry;
        let side = (n * n) as f64 * self.split_percent / 100.0 * (4.0 + 4.0 * ch as f64);
        let files = (dense * self.containers.len() as f64 + side) as u64;
        PlannedStage {
            stage: "encode".into(),
            // The transport (permuted in place), and a dense part only without hole filling
            // (with it the permuted transport is encoded in place of one); the split keeps
            // memory for its answer only (counted in `files`).
            peak_bytes: 4 * n * n * ch * if self.fill_holes { 1 } else { 2 } + files,
            output_bytes: files,
            notes: format!(
                "{} dense part, {} % sidecar",
                self.encoding.name(),
                self.split_percent
            ),
        }
    }
}
