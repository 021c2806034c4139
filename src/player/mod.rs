//! The runtime: load a baked directory and render frames with wgpu. The binary
//! (`relume-player`) only parses arguments and runs the window or headless loop around this.

pub mod camera_rig;
mod freeform;
pub mod headless;
mod mesh;
mod panel;
mod terrain;
pub mod window;

pub use freeform::FreeformPlayer;
pub use mesh::MeshPlayer;
pub use terrain::TerrainPlayer;

use crate::baked::Manifest;
use crate::error::Result;
use crate::gpu::timing::PassTimer;
use crate::gpu::Gpu;
use crate::render::camera::Camera;
use crate::render::mesh_reference::FrameSettings;
use serde::Serialize;
use std::path::Path;

/// The one sun model (`crate::terrain::sun`), also the player's: azimuth in degrees clockwise
/// from north, elevation above the horizon.
pub use crate::terrain::sun::Sun;

/// Which transport the runtime gathers from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum TransportChoice {
    /// The encoded transport when the bake has one, else the dense matrix.
    #[default]
    Auto,
    /// The uncompressed `transport.npy` (reference).
    Dense,
    /// The `encode` stage's output.
    Compressed,
}

/// How a bake is loaded.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct PlayerOptions {
    pub transport: TransportChoice,
    /// Force the BC decode path (None: hardware when the adapter has BC textures).
    pub decode: Option<crate::gpu::compressed_gather::DecodePath>,
}

/// What every loaded bake can do each frame.
pub enum Player {
    Mesh(Box<MeshPlayer>),
    Terrain(Box<TerrainPlayer>),
    /// A freeform scene file (`.ron`), cast live: nothing baked.
    Freeform(Box<FreeformPlayer>),
}

/// Wall and GPU times of one frame.
#[derive(Clone, Debug, Default, Serialize)]
pub struct FrameTimes {
    pub frame: u32,
    /// CPU wall time to record, submit and wait for the frame (ms).
    pub cpu_ms: f64,
    /// GPU time per pass from timestamp queries (ms); empty when the adapter has none.
    pub gpu_ms: Vec<(String, f64)>,
}

impl Player {
    /// Load the bake at `dir` (or the freeform scene file `dir`, a `.ron`) for a
    /// `width`×`height` target.
    pub fn load(
        gpu: &Gpu,
        dir: &Path,
        opts: &PlayerOptions,
        width: u32,
        height: u32,
    ) -> Result<Player> {
        if dir.is_file() && dir.extension().is_some_and(|e| e == "ron") {
            return Ok(Player::Freeform(Box::new(FreeformPlayer::load(
                gpu, dir, width, height,
            )?)));
        }
        let manifest = Manifest::read(dir)?;
        match manifest.pipeline.input.kind() {
            "scene" => Ok(Player::Mesh(Box::new(MeshPlayer::load(
                gpu, dir, &manifest, opts, width, height,
            )?))),
            _ => Ok(Player::Terrain(Box::new(TerrainPlayer::load(
                gpu, dir, &manifest, width, height,
            )?))),
        }
    }

    /// A camera that frames the bake.
    pub fn default_camera(&self) -> Camera {
        match self {
            Player::Mesh(m) => m.default_camera(),
            Player::Terrain(t) => t.default_camera(),
            Player::Freeform(f) => f.default_camera(),
        }
    }

    /// The size the fly camera's speed scales with: a mesh scene's bounding-box diagonal, else
    /// twice the default camera's distance to its target.
    pub fn diagonal(&self) -> f32 {
        match self {
            Player::Mesh(m) => {
                let (lo, hi) = m.scene.bounds();
                (hi - lo).length()
            }
            _ => {
                let c = self.default_camera();
                2.0 * (c.eye - c.target).length()
            }
        }
    }

    /// Add punctual lights to a mesh scene's own (e.g. from `--light`). Terrain is lit by the
    /// sun alone: lights there are refused.
    pub fn add_lights(&mut self, gpu: &Gpu, lights: &[crate::scene::Light]) -> Result<()> {
        if lights.is_empty() {
            return Ok(());
        }
        match self {
            Player::Mesh(m) => m.add_lights(gpu, lights),
            Player::Terrain(_) => Err(crate::error::Error::knob(
                "punctual lights (--light) light mesh bakes; a height-map bake is lit by the sun (--sun)",
            )),
            Player::Freeform(_) => Err(crate::error::Error::knob(
                "punctual lights (--light) light mesh bakes; a freeform scene is lit by the sun (--sun)",
            )),
        }
    }

    /// Set the sun (a directional light for mesh scenes).
    pub fn set_sun(&mut self, gpu: &Gpu, sun: Option<Sun>) -> Result<()> {
        match self {
            Player::Mesh(m) => m.set_sun(gpu, sun),
            Player::Terrain(t) => t.set_sun(gpu, sun),
            Player::Freeform(f) => {
                f.set_sun(sun);
                Ok(())
            }
        }
    }

    /// Set the animation phase in [0, 1] (a freeform scene's texture morph; other scenes have
    /// no animation).
    pub fn set_phase(&mut self, phase: f64) {
        if let Player::Freeform(f) = self {
            f.set_morph(phase);
        }
    }

    /// Set the animation frame of the theme borders of a terrain or freeform scene (still
    /// unless `s.theme_animation`); mesh scenes have none.
    pub fn set_frame(&mut self, gpu: &Gpu, frame: u32, s: &FrameSettings) {
        let frame = if s.theme_animation { frame } else { 0 };
        match self {
            Player::Terrain(t) => t.set_theme_frame(gpu, frame),
            Player::Freeform(f) => f.set_theme_frame(gpu, frame),
            Player::Mesh(_) => {}
        }
    }

    /// How a terrain frame with settings `s` computes its shadows (None for other scenes).
    pub fn terrain_shadows(&self, s: &FrameSettings) -> Option<&'static str> {
        let Player::Terrain(t) = self else {
            return None;
        };
        Some(if !s.shadows {
            "none"
        } else if s.soft_shadows {
            "soft"
        } else if s.horizon_shadows && t.renderer.has_horizon() {
            "horizon_maps"
        } else {
            "traversal"
        })
    }

    /// Render one frame into the player's target.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        camera: &Camera,
        s: &FrameSettings,
        timer: &mut PassTimer,
    ) -> Result<()> {
        match self {
            Player::Mesh(m) => m.render(gpu, camera, s, timer),
            Player::Terrain(t) => {
                t.settings.exposure = s.exposure;
                t.settings.shadows = s.shadows;
                t.settings.soft = s.soft_shadows;
                t.settings.horizon = s.horizon_shadows;
                t.settings.atmosphere = if s.fog {
                    s.atmosphere
                } else {
                    crate::atmosphere::Model::None
                };
                t.settings.themes = s.themes;
                t.render(gpu, camera, timer)
            }
            Player::Freeform(f) => f.render(gpu, camera, s, timer),
        }
    }

    /// The render target of the last frame.
    pub fn target_view(&self) -> &wgpu::TextureView {
        match self {
            Player::Mesh(m) => &m.renderer.target.view,
            Player::Terrain(t) => &t.renderer.target.view,
            Player::Freeform(f) => &f.target.view,
        }
    }

    /// Resize the render target.
    pub fn resize(&mut self, gpu: &Gpu, width: u32, height: u32) -> Result<()> {
        match self {
            Player::Mesh(m) => m.renderer.resize(gpu, width, height),
            Player::Terrain(t) => t.renderer.resize(gpu, width, height),
            Player::Freeform(f) => f.resize(gpu, width, height),
        }
        Ok(())
    }

    /// The render target's size in pixels.
    pub fn target_size(&self) -> (u32, u32) {
        let t = match self {
            Player::Mesh(m) => &m.renderer.target,
            Player::Terrain(t) => &t.renderer.target,
            Player::Freeform(f) => &f.target,
        };
        (t.width, t.height)
    }

    /// The log-luminance histogram of the last frame (automatic exposure).
    pub fn exposure_histogram(
        &self,
        gpu: &Gpu,
        meter: &crate::gpu::exposure::ExposureMeter,
    ) -> Result<[u32; crate::render::exposure::BINS]> {
        let (w, h) = self.target_size();
        meter.histogram(gpu, self.target_view(), w, h)
    }

    /// The last frame as an image.
    pub fn read_image(&self, gpu: &Gpu) -> Result<image::RgbaImage> {
        match self {
            Player::Mesh(m) => m.renderer.target.read_image(gpu),
            Player::Terrain(t) => t.renderer.target.read_image(gpu),
            Player::Freeform(f) => f.target.read_image(gpu),
        }
    }
}

/// Files of one bake that disagree: most likely copied together from different bakes.
fn mixed_bakes(dir: &Path, file: &str, has: String, other: String) -> crate::error::Error {
    crate::error::Error::input(
        dir.join(file),
        format!("{has}, but {other}: the files come from different bakes (bake again)"),
    )
}
