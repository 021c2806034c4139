//! The height-map stages: `minmax_mipmap`.

use super::{record, StageRun};
use crate::bake::estimate::{PlanState, PlannedStage};
use crate::bake::workspace::Workspace;
use crate::baked::{self, BakeTransaction, StageRecord};
use crate::error::Result;
use crate::pipeline::knobs::MinmaxMipmapKnobs;
use crate::progress::Progress;
use crate::terrain::minmax_mipmap::{level_sizes, MinMaxMipmap};

impl StageRun for MinmaxMipmapKnobs {
    fn run(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        progress: &dyn Progress,
    ) -> Result<StageRecord> {
        progress.begin("minmax_mipmap", 0);
        let mip = MinMaxMipmap::build(ws.heightmap()?);
        baked::mipmap::write(txn, &mip)?;
        let mut rec = record("minmax_mipmap", &[baked::mipmap::FILE]);
        rec.report.insert("levels".into(), mip.levels.len() as f64);
        rec.report
            .insert("level0_width".into(), mip.levels[0].width as f64);
        rec.report
            .insert("level0_height".into(), mip.levels[0].height as f64);
        rec.report
            .insert("texels".into(), (mip.data.len() / 2) as f64);
        rec.facts.insert(
            "layout".into(),
            "multi-part EXR, parts level0..: f32 channels max, min; level 0 = ceil(W/2) x ceil(H/2) \
             bounding 2x2 texels plus a one-texel border; each level halves the previous (2x2 reduction); no 1x1 level"
                .into(),
        );
        ws.set_mipmap(mip);
        progress.finish();
        Ok(rec)
    }

    fn estimate(&self, state: &mut PlanState) -> PlannedStage {
        let (w, h) = state.map_size;
        let sizes = level_sizes(w.max(1) as usize, h.max(1) as usize);
        let texels: u64 = sizes.iter().map(|(a, b)| (*a * *b) as u64).sum();
        let bytes = texels * 8;
        state.resident_bytes += bytes;
        PlannedStage {
            stage: "minmax_mipmap".into(),
            peak_bytes: bytes * 2,
            output_bytes: bytes / 2,
            notes: format!("{} levels, {} texels (max, min f32)", sizes.len(), texels),
        }
    }
}
