//! The height-map stages: `minmax_mipmap`, `horizon_maps`, `themes`.

use super::{record, StageRun};
use crate::bake::estimate::{PlanState, PlannedStage};
use crate::bake::workspace::Workspace;
use crate::baked::{self, BakeTransaction, StageRecord};
use crate::error::Result;
use crate::pipeline::knobs::{HorizonMapsKnobs, MinmaxMipmapKnobs, ThemesKnobs};
use crate::progress::Progress;
use crate::terrain::horizon::map::HorizonMap;
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

impl StageRun for HorizonMapsKnobs {
    fn run(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        progress: &dyn Progress,
    ) -> Result<StageRecord> {
        let settings = self.settings();
        progress.begin(baked::horizon::STAGE, settings.directions as u64);
        let hm = HorizonMap::build_with_progress(ws.heightmap()?, &settings, progress);
        progress.finish();
        baked::horizon::write(txn, &hm)?;
        let mut rec = record(
            baked::horizon::STAGE,
            &[baked::horizon::FILE, baked::horizon::DIRECTIONS],
        );
        rec.report
            .insert("directions".into(), hm.directions.len() as f64);
        rec.report
            .insert("planet_radius_m".into(), hm.planet_radius.unwrap_or(0.0));
        let worst = hm
            .directions
            .iter()
            .enumerate()
            .map(|(k, d)| {
                let want = k as f64 * 360.0 / hm.directions.len() as f64;
                let e = (d.azimuth_deg - want).rem_euclid(360.0);
                e.min(360.0 - e)
            })
            .fold(0.0f64, f64::max);
        rec.report.insert("azimuth_max_offset_deg".into(), worst);
        rec.facts.insert(
            "layout".into(),
            "horizon_maps.npy: u16 [N, H, W], angle = -90 + v*180/65535 degrees above the \
             horizontal toward direction k; horizon_directions.npy: i32 [N, 2] texel steps \
             (a east, b south), sorted by azimuth"
                .into(),
        );
        Ok(rec)
    }

    fn estimate(&self, state: &mut PlanState) -> PlannedStage {
        let (w, h) = state.map_size;
        let texels = w.max(1) * h.max(1);
        let n = self.directions as u64;
        let planes = texels * n * 2;
        // The planes held until written, one sweep's f32 angles, its line list and the written
        // file's buffer.
        let peak = planes + texels * 4 + texels * 16;
        PlannedStage {
            stage: baked::horizon::STAGE.into(),
            peak_bytes: peak,
            output_bytes: planes + n * 8,
            notes: format!("{n} directions x {texels} texels, u16"),
        }
    }
}

impl StageRun for ThemesKnobs {
    fn run(
        &self,
        ws: &mut Workspace,
        txn: &mut BakeTransaction,
        progress: &dyn Progress,
    ) -> Result<StageRecord> {
        progress.begin(baked::themes::STAGE, 0);
        let georef = ws.georef()?.cloned();
        let given = crate::load::themes::GivenHeightMap {
            map: ws.heightmap()?,
            georef: georef.as_ref(),
            name: "the pipeline's height map",
        };
        let set = crate::load::themes::load_themes(&self.file, Some(given))?;
        baked::themes::write(txn, &set)?;
        progress.finish();
        let mut rec = record(baked::themes::STAGE, &[baked::themes::FILE]);
        let base = &set.index.levels[0];
        let m = set.memory();
        rec.report.insert("themes".into(), set.themes.len() as f64);
        rec.report
            .insert("classes".into(), set.classes.len() as f64);
        rec.report.insert("index_width".into(), base.width as f64);
        rec.report.insert("index_height".into(), base.height as f64);
        rec.report
            .insert("index_levels".into(), set.index.levels.len() as f64);
        rec.report
            .insert("bytes_index_ccc".into(), m.index_ccc as f64);
        rec.report
            .insert("bytes_index_raw".into(), m.index_raw as f64);
        rec.report.insert("bytes_total".into(), m.total as f64);
        rec.report.insert(
            "bytes_global_rgb8_index_res".into(),
            m.global_rgb8_index_res as f64,
        );
        rec.facts.insert(
            "layout".into(),
            "themes.bin: RLTHEME1, u32 header length, JSON header, level-0 index map as CCC words \
             (u32) + exception blocks (16 B), theme texels RGBA8 (mip chains), turbulence f32 pairs"
                .into(),
        );
        Ok(rec)
    }

    fn estimate(&self, state: &mut PlanState) -> PlannedStage {
        // The index map at the height map's size (a Rules map; other sources are usually no
        // larger), its levels (4/3) and its compressed copy, plus a 256² noise map and
        // textures.
        let (w, h) = state.map_size;
        let texels = w.max(1) * h.max(1);
        PlannedStage {
            stage: baked::themes::STAGE.into(),
            peak_bytes: texels * 2 + (1 << 20) * 2,
            output_bytes: texels / 4 + (1 << 20),
            notes: format!("index map of about {texels} texels, CCC"),
        }
    }
}
