//! The window's panel wiring: what the panel edits is gathered from the app, the panel runs
//! ([`crate::player::panel::show`]), and its changes are applied (lights re-uploaded, the sun
//! moved, the camera switched, a screenshot written).

use super::App;
use crate::error::{Error, Result};
use crate::gpu::Gpu;
use crate::player::camera_rig::Fly;
use crate::player::panel::{self, Changes, PanelView};
use crate::player::Player;

impl App {
    /// Draw the panel over `view` (the surface texture, holding the frame) and apply what it
    /// changed.
    pub(super) fn panel(&mut self, view: &wgpu::TextureView) -> Result<()> {
        let Some(r) = self.running.as_mut() else {
            return Ok(());
        };
        let mut lights = match &r.player {
            Player::Mesh(m) => Some(m.lights.clone()),
            _ => None,
        };
        let camera_arg = r.camera().to_arg();
        let terrain = matches!(r.player, Player::Terrain(_));
        let size = [r.config.width, r.config.height];
        let (fly_speed, fov) = match r.fly.as_mut() {
            Some(f) => (Some(&mut f.speed), &mut f.fov),
            None => (None, &mut r.orbit.fov),
        };
        let mut v = PanelView {
            lights: lights.as_mut(),
            sun: &mut self.sun,
            sun_on: &mut self.sun_on,
            settings: &mut self.plan.settings,
            exposure: &mut self.plan.exposure,
            terrain,
            fly: fly_speed.is_some(),
            fly_speed,
            fov,
            camera_arg: camera_arg.clone(),
            frame_ms: &r.history,
            pass_ms: &r.pass_ms,
        };
        let mut ch = Changes::default();
        let rects = &mut r.rects;
        r.layer.draw(&r.gpu, &r.window, view, size, |ui| {
            ch = panel::show(ui, &mut v, rects);
        });
        if ch.lights {
            if let (Player::Mesh(m), Some(l)) = (&mut r.player, &lights) {
                m.set_lights(&r.gpu, l)?;
            }
        }
        if ch.sun {
            r.player.set_sun(&r.gpu, self.sun_on.then_some(self.sun))?;
        }
        if ch.toggle_fly {
            self.toggle_fly();
        }
        if ch.copy_camera {
            if let Some(r) = self.running.as_ref() {
                r.layer.ctx.copy_text(camera_arg.clone());
            }
            eprintln!("--camera={camera_arg}");
        }
        if ch.screenshot {
            self.screenshot()?;
        }
        Ok(())
    }

    /// Switch between the orbit and the fly camera (`F`, the panel's camera button).
    pub(super) fn toggle_fly(&mut self) {
        if let Some(r) = self.running.as_mut() {
            r.fly = match r.fly {
                Some(_) => None,
                None => Some(Fly::from_camera(&r.orbit.camera(), r.diagonal)),
            };
            r.held = Default::default();
        }
    }

    /// Write the player's frame (without the panel) beside the bake: `NAME-shot-NNNN.png` in
    /// the bake directory's parent (the bake itself is never written to).
    pub(super) fn screenshot(&mut self) -> Result<()> {
        let Some(r) = self.running.as_mut() else {
            return Ok(());
        };
        let dir = &self.plan.dir;
        let name = dir
            .file_stem()
            .map_or_else(|| "relume".into(), |n| n.to_string_lossy().into_owned());
        let parent = dir
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(std::path::Path::new("."));
        let path = loop {
            r.shots += 1;
            let p = parent.join(format!("{name}-shot-{:04}.png", r.shots));
            if !p.exists() {
                break p;
            }
            if r.shots > 9999 {
                return Err(Error::knob(
                    "9,999 screenshots exist beside the bake already",
                ));
            }
        };
        super::super::headless::write_png(&path, &r.player.read_image(&r.gpu)?)?;
        eprintln!("screenshot: {}", path.display());
        Ok(())
    }
}

/// Write the surface texture `t` (RGBA8 or BGRA8, created with `COPY_SRC`) as a PNG.
pub(super) fn write_surface(gpu: &Gpu, t: &wgpu::Texture, path: &std::path::Path) -> Result<()> {
    if !t.usage().contains(wgpu::TextureUsages::COPY_SRC) {
        return Err(Error::unsupported(
            path,
            "this window surface cannot be copied from",
        ));
    }
    let mut px = crate::gpu::readback::read_texture_4bpp(gpu, t)?;
    if matches!(
        t.format(),
        wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
    ) {
        px.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
    }
    px.chunks_exact_mut(4).for_each(|p| p[3] = 255);
    let img = image::RgbaImage::from_raw(t.width(), t.height(), px)
        .ok_or_else(|| Error::Internal("surface readback size".into()))?;
    super::super::headless::write_png(path, &img)
}
