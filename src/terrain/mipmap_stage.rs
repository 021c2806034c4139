//! The `minmax_mipmap` pipeline stage: build the min/max mipmap of the bake's height map and
//! write it as `minmax_mipmap.exr` (layout in docs/baked-format.md).

use super::minmax_mipmap::{level_sizes, MinMaxMipmap};
use crate::baked::{BakeTransaction, StageRecord};
use crate::error::Result;
use crate::pipeline::{PlanState, PlannedStage, StageRun};
use crate::progress::Progress;
use crate::workspace::Workspace;
use serde::{Deserialize, Serialize};

/// File name of the mipmap in a height-map bake.
pub const MIPMAP_FILE: &str = "minmax_mipmap.exr";

/// Knobs of the `minmax_mipmap` stage (none yet: `MinmaxMipmap()` in a pipeline).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MinmaxMipmapKnobs {}

/// The mipmap of a bake: from this run's workspace or read from the bake's file.
pub fn mipmap_of(ws: &mut Workspace) -> Result<&MinMaxMipmap> {
    ws.get(MIPMAP_FILE, MinMaxMipmap::read_exr)
}

impl StageRun for MinmaxMipmapKnobs {
    fn run(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        progress: &dyn Progress,
    ) -> Result<StageRecord> {
        progress.begin("minmax_mipmap", 0);
        let mip = MinMaxMipmap::build(ws.heightmap()?);
        txn.write_with(MIPMAP_FILE, |p| mip.write_exr(p))?;
        let mut rec = StageRecord {
            stage: "minmax_mipmap".into(),
            outputs: vec![MIPMAP_FILE.into()],
            ..Default::default()
        };
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
        ws.put(MIPMAP_FILE, mip);
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
