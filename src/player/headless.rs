//! Headless rendering: frames to PNG and `frames.json` (adapter, per-frame CPU time and per-pass
//! GPU timestamps). `relume-player --headless` and `benches/player_frames.rs` share it.

use super::{FrameTimes, Player, PlayerOptions, Sun};
use crate::baked::images::write_atomic;
use crate::error::{Error, Result};
use crate::gpu::exposure::ExposureMeter;
use crate::gpu::timing::PassTimer;
use crate::gpu::{AdapterReport, Gpu};
use crate::render::camera::Camera;
use crate::render::exposure::{self, AutoExposure, Exposure};
use crate::render::mesh_reference::FrameSettings;
use crate::scene::Light;
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

/// What to render headless.
#[derive(Clone, Debug)]
pub struct HeadlessPlan {
    pub dir: PathBuf,
    pub out: PathBuf,
    pub size: (u32, u32),
    pub frames: u32,
    /// The sun of frame 0; it turns a full circle in azimuth over the frames.
    pub sun: Option<Sun>,
    pub lights: Vec<Light>,
    /// Default: the player's framing of the scene.
    pub camera: Option<Camera>,
    /// `settings.exposure` is ignored: fixed here, or found once from frame 0 and kept for
    /// every frame (an animation does not flicker).
    pub settings: FrameSettings,
    pub exposure: Exposure,
    pub options: PlayerOptions,
}

/// `frames.json`.
#[derive(Clone, Debug, Serialize)]
pub struct HeadlessReport {
    pub adapter: AdapterReport,
    pub size: [u32; 2],
    /// The view, as the `--camera` argument that gives it back.
    pub camera: String,
    /// Terrain: how shadows were computed (`horizon_maps`, `traversal`, `soft`, `none`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub terrain_shadows: Option<&'static str>,
    pub note: &'static str,
    /// The exposure every frame was drawn with, and how it was set (`fixed` or `auto`).
    pub exposure: f32,
    pub exposure_mode: &'static str,
    /// Automatic exposure: the frames drawn to find it (1 = the first guess held).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exposure_tries: Option<usize>,
    pub frames: Vec<FrameTimes>,
}

/// The sun of frame `f` of `frames`: `sun` turned by `360° · f / frames` in azimuth.
pub fn sun_of_frame(sun: Sun, f: u32, frames: u32) -> Sun {
    Sun {
        azimuth_deg: sun.azimuth_deg + 360.0 * f as f64 / frames.max(1) as f64,
        ..sun
    }
}

/// Render every frame of `plan` into `plan.out` (`frame_NNNN.png`, then `frames.json`).
pub fn render_frames(gpu: &Gpu, plan: &HeadlessPlan) -> Result<HeadlessReport> {
    let (w, h) = plan.size;
    let mut player = Player::load(gpu, &plan.dir, &plan.options, w, h)?;
    player.add_lights(gpu, &plan.lights)?;
    // The first view may depend on the sun (terrain): frame 0's.
    player.set_sun(gpu, plan.sun.map(|s| sun_of_frame(s, 0, plan.frames)))?;
    let camera = plan.camera.unwrap_or_else(|| player.default_camera());
    std::fs::create_dir_all(&plan.out)
        .map_err(|e| Error::io(&plan.out, "cannot create output directory", e))?;
    let mut timer = PassTimer::new(gpu, 48);
    let mut settings = plan.settings;
    let (mode, tries) = match plan.exposure {
        Exposure::Fixed(e) => {
            settings.exposure = e;
            ("fixed", None)
        }
        Exposure::Auto(a) => {
            player.set_sun(gpu, plan.sun.map(|s| sun_of_frame(s, 0, plan.frames)))?;
            player.set_phase(0.0);
            player.set_frame(gpu, 0, &settings);
            let meter = ExposureMeter::new(gpu)?;
            let (e, tries) =
                find_exposure(gpu, &mut player, &meter, &camera, &settings, &a, &mut timer)?;
            settings.exposure = e;
            ("auto", Some(tries))
        }
    };
    let mut frames = Vec::new();
    for f in 0..plan.frames {
        let sun = plan.sun.map(|s| sun_of_frame(s, f, plan.frames));
        let t0 = Instant::now();
        player.set_sun(gpu, sun)?;
        player.set_phase(f as f64 / (plan.frames.max(2) - 1) as f64);
        player.set_frame(gpu, f, &settings);
        player.render(gpu, &camera, &settings, &mut timer)?;
        let cpu_ms = t0.elapsed().as_secs_f64() * 1e3;
        let gpu_ms = timer
            .read(gpu)?
            .into_iter()
            .map(|(n, t)| (n.to_string(), t))
            .collect();
        let img = player.read_image(gpu)?;
        write_png(&plan.out.join(format!("frame_{f:04}.png")), &img)?;
        frames.push(FrameTimes {
            frame: f,
            cpu_ms,
            gpu_ms,
        });
    }
    let report = HeadlessReport {
        adapter: gpu.info.clone(),
        size: [w, h],
        camera: camera.to_arg(),
        terrain_shadows: player.terrain_shadows(&plan.settings),
        note: "cpu_ms is wall time to record, submit and wait; on a software rasteriser (llvmpipe/lavapipe) these are CPU times, not GPU times",
        exposure: settings.exposure,
        exposure_mode: mode,
        exposure_tries: tries,
        frames,
    };
    let json = serde_json::to_string_pretty(&report).expect("report serialises");
    write_atomic(&plan.out.join("frames.json"), |tmp| {
        std::fs::write(tmp, json.as_bytes()).map_err(|e| Error::io(tmp, "cannot write", e))
    })?;
    Ok(report)
}

/// Automatic exposure for one view: draw it, measure, and draw again with the exposure the
/// histogram asks for until two successive exposures agree within
/// [`exposure::SETTLED_EV`] stops (at most [`exposure::MAX_TRIES`] frames). Starts from
/// `s.exposure`. Returns the exposure and the frames drawn.
pub fn find_exposure(
    gpu: &Gpu,
    player: &mut Player,
    meter: &ExposureMeter,
    camera: &Camera,
    s: &FrameSettings,
    auto: &AutoExposure,
    timer: &mut PassTimer,
) -> Result<(f32, usize)> {
    let mut s = *s;
    for tries in 1..=exposure::MAX_TRIES {
        player.render(gpu, camera, &s, timer)?;
        timer.read(gpu)?;
        let next =
            exposure::next_exposure(&player.exposure_histogram(gpu, meter)?, s.exposure, auto);
        if (next / s.exposure).log2().abs() <= exposure::SETTLED_EV {
            return Ok((s.exposure, tries));
        }
        s.exposure = next;
    }
    Ok((s.exposure, exposure::MAX_TRIES))
}

pub use crate::baked::images::write_png_rgba as write_png;
