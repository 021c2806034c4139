//! Height-map bakes at runtime: the height field as a mesh with per-pixel relief shadows (hard
//! from the horizon maps when baked, else by the accelerated traversal over the min/max mipmap;
//! or soft by branch-and-bound), shadow
//! brightness k_shadow, thematic textures (animated borders) when baked, aerial perspective;
//! the sun moves freely.

use crate::baked::{self, Manifest};
use crate::error::Result;
use crate::gpu::terrain_renderer::TerrainRenderer;
use crate::gpu::timing::PassTimer;
use crate::gpu::Gpu;
use crate::heightmap::HeightMap;
use crate::render::camera::Camera;
use crate::render::terrain_shading::TerrainSettings;
use crate::terrain::sun::Sun;
use crate::terrain::MinMaxMipmap;
use std::path::Path;

/// A loaded height-map bake.
pub struct TerrainPlayer {
    pub map: HeightMap,
    pub mip: MinMaxMipmap,
    pub renderer: TerrainRenderer,
    pub settings: TerrainSettings,
    /// The bake's theme set (`themes.bin`), when it has one.
    pub themes: Option<crate::theme::ThemeSet>,
    /// The sun of the last [`TerrainPlayer::set_sun`].
    pub sun: Sun,
}

/// The sun when none is given.
pub const DEFAULT_SUN: Sun = Sun {
    azimuth_deg: 300.0,
    elevation_deg: 10.0,
};

impl TerrainPlayer {
    /// Load `heightmap.exr`, `minmax_mipmap.exr` (built here when the bake has none) and the
    /// horizon maps when the bake has them.
    pub fn load(
        gpu: &Gpu,
        dir: &Path,
        manifest: &Manifest,
        width: u32,
        height: u32,
    ) -> Result<Self> {
        let map = baked::heightmap::read(dir, manifest)?;
        let mip = if manifest.file(baked::mipmap::FILE).is_some() {
            baked::mipmap::read(dir)?
        } else {
            MinMaxMipmap::build(&map)
        };
        if (mip.map_width, mip.map_height) != (map.width, map.height) {
            return Err(super::mixed_bakes(
                dir,
                baked::mipmap::FILE,
                format!(
                    "is the mipmap of a {}x{} map",
                    mip.map_width, mip.map_height
                ),
                format!("{} is {}x{}", baked::heightmap::FILE, map.width, map.height),
            ));
        }
        let mut renderer = TerrainRenderer::new(gpu, &map, &mip, width, height, None)?;
        if manifest.file(baked::horizon::FILE).is_some() {
            let hm = baked::horizon::read(dir, manifest, (map.width, map.height), map.cell_size)?;
            renderer.set_horizon(gpu, hm)?;
        }
        let themes = if manifest.file(baked::themes::FILE).is_some() {
            let set = baked::themes::read(dir)?;
            renderer.set_themes(gpu, &set);
            Some(set)
        } else {
            None
        };
        Ok(TerrainPlayer {
            map,
            mip,
            renderer,
            settings: TerrainSettings::default(),
            themes,
            sun: DEFAULT_SUN,
        })
    }

    /// A low oblique view of the map's most rugged part from the side where the current sun
    /// shows the most relief ([`crate::render::terrain_view`]).
    pub fn default_camera(&self) -> Camera {
        crate::render::terrain_view::relief_view(
            &self.map,
            &self.sun,
            self.settings.vertical_exaggeration,
        )
    }

    /// Set the sun (default: azimuth 300°, elevation 10°).
    pub fn set_sun(&mut self, gpu: &Gpu, sun: Option<Sun>) -> Result<()> {
        let s = sun.unwrap_or(DEFAULT_SUN);
        self.sun = Sun::new(s.azimuth_deg, s.elevation_deg)?;
        self.renderer.set_sun(gpu, self.sun);
        Ok(())
    }

    /// Move the theme borders to animation frame `frame` (0 = still).
    pub fn set_theme_frame(&mut self, gpu: &Gpu, frame: u32) {
        if let Some(set) = &self.themes {
            self.renderer.set_theme_shift(gpu, set.shift(frame));
        }
    }

    /// Record and submit one frame.
    pub fn render(&mut self, gpu: &Gpu, camera: &Camera, timer: &mut PassTimer) -> Result<()> {
        timer.reset();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        let vp = camera.view_projection(self.renderer.target.width, self.renderer.target.height);
        self.renderer
            .record(gpu, &mut enc, vp, camera.eye, &self.settings, timer)?;
        timer.resolve(&mut enc);
        gpu.queue.submit([enc.finish()]);
        gpu.wait();
        Ok(())
    }
}
