//! The interactive window (winit): orbit and fly cameras ([`super::camera_rig`]), sun keys,
//! toggles, frame time in the title.

use crate::error::{Error, Result};
use crate::gpu::blit::Blit;
use crate::gpu::exposure::ExposureMeter;
use crate::gpu::timing::PassTimer;
use crate::gpu::{BackendChoice, Gpu};
use crate::player::camera_rig::{Fly, Held, Orbit};
use crate::player::panel::{self, layer::Layer, script::Script, WidgetRects};
use crate::player::{Player, PlayerOptions, Sun};
use crate::render::camera::Camera;
use crate::render::exposure::{self, Exposure};
use crate::render::mesh_reference::FrameSettings;
use crate::scene::Light;
use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

mod with_panel;

struct Running {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    gpu: Gpu,
    player: Player,
    blit: Blit,
    timer: PassTimer,
    orbit: Orbit,
    /// The fly camera, while it is the one in use (`F` switches).
    fly: Option<Fly>,
    held: Held,
    last: Instant,
    last_frame: Instant,
    frame_ms: f64,
    /// The scene's bounding-box diagonal (the fly camera's speed scale).
    diagonal: f32,
    meter: ExposureMeter,
    layer: Layer,
    /// The panel is shown (`Tab` hides it).
    panel_on: bool,
    rects: WidgetRects,
    /// Recent frame times (ms) and the last frame's GPU time per pass, for the panel.
    history: VecDeque<f32>,
    pass_ms: Vec<(&'static str, f64)>,
    script: Script,
    /// Screenshots written so far (their numbers).
    shots: u32,
}

impl Running {
    fn camera(&self) -> Camera {
        match &self.fly {
            Some(f) => f.camera(),
            None => self.orbit.camera(),
        }
    }
}

/// What the window shows, from the command line.
pub struct WindowPlan {
    pub dir: PathBuf,
    pub size: (u32, u32),
    pub sun: Option<Sun>,
    pub camera: Option<Camera>,
    /// `settings.exposure` is the first frame's when `exposure` is automatic.
    pub settings: FrameSettings,
    pub exposure: Exposure,
    pub backend: Option<BackendChoice>,
    pub options: PlayerOptions,
    /// Punctual lights added to the scene's (`--light`).
    pub lights: Vec<Light>,
    /// Close the window after this many frames (`--exit-after`; scripts and tests).
    pub exit_after: Option<u32>,
    /// Scripted panel input (`--panel-script`, [`panel::script`]).
    pub panel_script: Option<PathBuf>,
    /// Show the panel from the start (`--no-panel` hides it; `Tab` toggles).
    pub panel: bool,
}

struct App {
    plan: WindowPlan,
    /// The sun the keys move (shown when `sun_on`).
    sun: Sun,
    sun_on: bool,
    frames: u32,
    running: Option<Running>,
    error: Option<Error>,
    dragging: Option<(f64, f64)>,
    cursor: (f64, f64),
}

/// Open a window on the bake at `dir` and run until it is closed.
pub fn run(plan: WindowPlan) -> Result<()> {
    let event_loop = EventLoop::new().map_err(|e| {
        Error::Gpu(format!(
            "cannot open a window ({e}); without a display use --headless"
        ))
    })?;
    let mut app = App {
        sun: plan.sun.unwrap_or(Sun {
            azimuth_deg: 135.0,
            elevation_deg: 35.0,
        }),
        sun_on: plan.sun.is_some(),
        plan,
        frames: 0,
        running: None,
        error: None,
        dragging: None,
        cursor: (0.0, 0.0),
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| Error::Gpu(format!("window event loop failed: {e}")))?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

impl App {
    fn start(&mut self, el: &ActiveEventLoop) -> Result<Running> {
        let attrs = Window::default_attributes()
            .with_title("relume-player")
            .with_inner_size(winit::dpi::PhysicalSize::new(
                self.plan.size.0,
                self.plan.size.1,
            ));
        let window = Arc::new(
            el.create_window(attrs)
                .map_err(|e| Error::Gpu(format!("cannot create a window: {e}")))?,
        );
        let desc = crate::gpu::instance_descriptor(self.plan.backend);
        let instance = wgpu::Instance::new(desc);
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| Error::Gpu(format!("cannot create a surface: {e}")))?;
        let gpu = Gpu::from_instance(&instance, Some(&surface))?;
        let caps = surface.get_capabilities(&gpu.adapter);
        // The shaders encode sRGB themselves: prefer a non-sRGB surface format.
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| !f.is_srgb())
            .unwrap_or(caps.formats[0]);
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            // Copies out of the surface serve the panel script's `window` step.
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | (caps.usages & wgpu::TextureUsages::COPY_SRC),
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&gpu.device, &config);
        let mut player = Player::load(
            &gpu,
            &self.plan.dir,
            &self.plan.options,
            config.width,
            config.height,
        )?;
        player.add_lights(&gpu, &self.plan.lights)?;
        player.set_sun(&gpu, self.sun_on.then_some(self.sun))?;
        eprintln!(
            "adapter: {} ({}, {})",
            gpu.info.name, gpu.info.backend, gpu.info.device_type
        );
        let camera = self.plan.camera.unwrap_or_else(|| player.default_camera());
        let orbit = Orbit::from_camera(&camera);
        let blit = Blit::new(&gpu, format)?;
        let mut timer = PassTimer::new(&gpu, 48);
        let meter = ExposureMeter::new(&gpu)?;
        match self.plan.exposure {
            Exposure::Fixed(e) => self.plan.settings.exposure = e,
            Exposure::Auto(a) => {
                // The first frame starts from the headless one-shot value; later frames follow.
                let (e, _) = super::headless::find_exposure(
                    &gpu,
                    &mut player,
                    &meter,
                    &camera,
                    &self.plan.settings,
                    &a,
                    &mut timer,
                )?;
                self.plan.settings.exposure = e;
            }
        }
        let diagonal = player.diagonal();
        let layer = Layer::new(&gpu, &window, format);
        let script = match &self.plan.panel_script {
            Some(p) => Script::read(p)?,
            None => Script::default(),
        };
        Ok(Running {
            window,
            surface,
            config,
            gpu,
            player,
            blit,
            timer,
            orbit,
            fly: None,
            held: Held::default(),
            last: Instant::now(),
            last_frame: Instant::now(),
            frame_ms: 0.0,
            diagonal,
            meter,
            layer,
            panel_on: self.plan.panel,
            rects: WidgetRects::new(),
            history: VecDeque::new(),
            pass_ms: Vec::new(),
            script,
            shots: 0,
        })
    }

    /// Draw one frame; true when `--exit-after` frames have been shown.
    fn redraw(&mut self) -> Result<bool> {
        let Some(r) = self.running.as_mut() else {
            return Ok(false);
        };
        let t0 = Instant::now();
        // Seconds since the last frame, capped so that a stall does not fling the camera.
        let dt = t0.duration_since(r.last_frame).as_secs_f32().min(0.1);
        r.last_frame = t0;
        if let Some(f) = r.fly.as_mut() {
            f.step(r.held, dt);
        }
        r.player.set_frame(&r.gpu, self.frames, &self.plan.settings);
        let camera = r.camera();
        r.player
            .render(&r.gpu, &camera, &self.plan.settings, &mut r.timer)?;
        if let Exposure::Auto(a) = self.plan.exposure {
            // Follow the light: brighter in about a third of a second, darker in one.
            let used = self.plan.settings.exposure;
            let target =
                exposure::next_exposure(&r.player.exposure_histogram(&r.gpu, &r.meter)?, used, &a);
            let tau = if target > used { 1.0 } else { 0.33 };
            self.plan.settings.exposure = exposure::smooth(used, target, dt, tau);
        }
        let frame = match r.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f)
            | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            _ => {
                r.surface.configure(&r.gpu.device, &r.config);
                r.window.request_redraw();
                return Ok(false);
            }
        };
        let view = frame.texture.create_view(&Default::default());
        r.blit.draw(&r.gpu, r.player.target_view(), &view);
        for step in r.script.due(self.frames) {
            match step {
                panel::script::Step::Pointer { label, pressed } => {
                    let rect = r.rects.get(label).ok_or_else(|| {
                        Error::knob(format!(
                            "the panel script names `{label}`, which the panel does not show"
                        ))
                    })?;
                    r.layer
                        .injected
                        .extend(panel::script::pointer_events(*rect, *pressed));
                }
                panel::script::Step::Screenshot(path) => {
                    super::headless::write_png(path, &r.player.read_image(&r.gpu)?)?;
                }
                panel::script::Step::Window(_) => {}
            }
        }
        if r.panel_on {
            self.panel(&view)?;
        }
        let Some(r) = self.running.as_mut() else {
            return Ok(false);
        };
        for step in r.script.due(self.frames) {
            if let panel::script::Step::Window(path) = step {
                with_panel::write_surface(&r.gpu, &frame.texture, path)?;
            }
        }
        r.gpu.queue.present(frame);
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        r.frame_ms = 0.9 * r.frame_ms + 0.1 * ms;
        r.history.push_back(ms as f32);
        if r.history.len() > 240 {
            r.history.pop_front();
        }
        if r.gpu.info.timestamps {
            r.pass_ms = r.timer.read(&r.gpu)?;
        }
        if r.last.elapsed().as_millis() > 250 {
            r.last = Instant::now();
            let s = &self.plan.settings;
            let mode = match &r.fly {
                Some(f) => format!("fly {:.2} m/s", f.speed),
                None => "orbit".into(),
            };
            let exposure = match self.plan.exposure {
                Exposure::Auto(a) => format!(
                    "exposure {:.3} (auto {:+.1} EV)",
                    s.exposure, a.compensation_ev
                ),
                Exposure::Fixed(_) => format!("exposure {:.3}", s.exposure),
            };
            r.window.set_title(&format!(
                "relume-player — {:.1} ms/frame — {mode} — {exposure} — sun {:.0}°/{:.0}°{} — direct {} indirect {} shadows {} emission {} textures {}",
                r.frame_ms,
                self.sun.azimuth_deg,
                self.sun.elevation_deg,
                if self.sun_on { "" } else { " (off)" },
                on(s.direct),
                on(s.indirect),
                on(s.shadows),
                on(s.emission),
                on(s.textures)
            ));
        }
        r.window.request_redraw();
        self.frames += 1;
        Ok(self.plan.exit_after.is_some_and(|n| self.frames >= n))
    }

    fn key(&mut self, key: &Key) -> Result<bool> {
        if *key == Key::Named(NamedKey::F12) {
            self.screenshot()?;
            return Ok(false);
        }
        let Some(r) = self.running.as_mut() else {
            return Ok(false);
        };
        let mut sun_changed = false;
        if let Key::Character(c) = key {
            match c.to_ascii_lowercase().as_str() {
                "f" => {
                    self.toggle_fly();
                    return Ok(false);
                }
                "t" => {
                    self.plan.settings.textures = !self.plan.settings.textures;
                    return Ok(false);
                }
                "w" | "a" | "s" | "d" | "q" | "e" if r.fly.is_some() => return Ok(false),
                _ => {}
            }
        }
        match key {
            Key::Named(NamedKey::Escape) => return Ok(true),
            Key::Named(NamedKey::Tab) => r.panel_on = !r.panel_on,
            Key::Named(NamedKey::ArrowLeft) => r.orbit.azimuth -= 5.0,
            Key::Named(NamedKey::ArrowRight) => r.orbit.azimuth += 5.0,
            Key::Named(NamedKey::ArrowUp) => {
                r.orbit.elevation = (r.orbit.elevation + 5.0).min(89.0)
            }
            Key::Named(NamedKey::ArrowDown) => {
                r.orbit.elevation = (r.orbit.elevation - 5.0).max(-89.0)
            }
            Key::Character(c) => match c.as_str() {
                "+" | "=" => r.orbit.distance *= 0.9,
                "-" => r.orbit.distance /= 0.9,
                "j" | "J" => {
                    (self.sun.azimuth_deg, sun_changed) = (self.sun.azimuth_deg - 5.0, true)
                }
                "l" | "L" => {
                    (self.sun.azimuth_deg, sun_changed) = (self.sun.azimuth_deg + 5.0, true)
                }
                "i" | "I" => {
                    (self.sun.elevation_deg, sun_changed) =
                        ((self.sun.elevation_deg + 2.0).min(90.0), true)
                }
                "k" | "K" => {
                    (self.sun.elevation_deg, sun_changed) =
                        ((self.sun.elevation_deg - 2.0).max(-10.0), true)
                }
                "s" | "S" => (self.sun_on, sun_changed) = (!self.sun_on, true),
                "1" => self.plan.settings.direct = !self.plan.settings.direct,
                "2" => self.plan.settings.indirect = !self.plan.settings.indirect,
                "3" => self.plan.settings.shadows = !self.plan.settings.shadows,
                "4" => self.plan.settings.emission = !self.plan.settings.emission,
                "5" => self.plan.settings.soft_shadows = !self.plan.settings.soft_shadows,
                "6" => self.plan.settings.fog = !self.plan.settings.fog,
                "7" => self.plan.settings.horizon_shadows = !self.plan.settings.horizon_shadows,
                "8" => self.plan.settings.themes = !self.plan.settings.themes,
                "9" => self.plan.settings.theme_animation = !self.plan.settings.theme_animation,
                "0" => {
                    use crate::atmosphere::Model;
                    self.plan.settings.atmosphere = match self.plan.settings.atmosphere {
                        Model::Fog => Model::FogPerPixel,
                        Model::FogPerPixel => Model::Hillaire,
                        Model::Hillaire | Model::None => Model::Fog,
                    }
                }
                "[" | "]" => {
                    let up = c.as_str() == "]";
                    match &mut self.plan.exposure {
                        Exposure::Auto(a) => a.compensation_ev += if up { 1.0 } else { -1.0 } / 3.0,
                        Exposure::Fixed(e) => {
                            *e *= if up { 1.25 } else { 0.8 };
                            self.plan.settings.exposure = *e;
                        }
                    }
                }
                "x" | "X" => {
                    self.plan.exposure = match self.plan.exposure {
                        Exposure::Auto(_) => Exposure::Fixed(self.plan.settings.exposure),
                        Exposure::Fixed(_) => Exposure::default(),
                    }
                }
                _ => {}
            },
            _ => {}
        }
        if sun_changed {
            self.sun_on |=
                !matches!(key, Key::Character(c) if c.as_str().eq_ignore_ascii_case("s"));
            r.player.set_sun(&r.gpu, self.sun_on.then_some(self.sun))?;
        }
        Ok(false)
    }
}

/// Record a movement key going down or up (W A S D, Q E, Shift); other keys change nothing.
fn hold(held: &mut Held, key: &Key, down: bool) {
    match key {
        Key::Named(NamedKey::Shift) => held.fast = down,
        Key::Character(c) => match c.to_ascii_lowercase().as_str() {
            "w" => held.forward = down,
            "s" => held.back = down,
            "a" => held.left = down,
            "d" => held.right = down,
            "q" => held.down = down,
            "e" => held.up = down,
            _ => {}
        },
        _ => {}
    }
}

fn on(b: bool) -> &'static str {
    if b {
        "on"
    } else {
        "off"
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.running.is_none() {
            match self.start(el) {
                Ok(r) => {
                    r.window.request_redraw();
                    self.running = Some(r);
                }
                Err(e) => {
                    self.error = Some(e);
                    el.exit();
                }
            }
        }
    }

    fn window_event(&mut self, el: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        // The panel sees every event first; what it uses (a click on a widget, typing in a
        // field) does not reach the camera or the keys.
        if let Some(r) = self.running.as_mut() {
            let used = r.layer.on_event(&r.window, &event);
            let input = matches!(
                event,
                WindowEvent::KeyboardInput { .. }
                    | WindowEvent::MouseInput { .. }
                    | WindowEvent::MouseWheel { .. }
                    | WindowEvent::CursorMoved { .. }
            );
            let tab = matches!(&event, WindowEvent::KeyboardInput { event: k, .. }
                if k.logical_key == Key::Named(NamedKey::Tab));
            if r.panel_on && used && input && !tab {
                if matches!(event, WindowEvent::CursorMoved { .. }) {
                    self.dragging = None;
                }
                return;
            }
        }
        let result = match event {
            WindowEvent::CloseRequested => {
                el.exit();
                Ok(())
            }
            WindowEvent::Resized(size) => {
                if let Some(r) = self.running.as_mut() {
                    r.config.width = size.width.max(1);
                    r.config.height = size.height.max(1);
                    r.surface.configure(&r.gpu.device, &r.config);
                    r.player.resize(&r.gpu, r.config.width, r.config.height)
                } else {
                    Ok(())
                }
            }
            WindowEvent::RedrawRequested => match self.redraw() {
                Ok(true) => {
                    eprintln!("showed {} frame(s) in a window", self.frames);
                    el.exit();
                    Ok(())
                }
                Ok(false) => Ok(()),
                Err(e) => Err(e),
            },
            WindowEvent::KeyboardInput { event, .. } => {
                if let Some(r) = self.running.as_mut() {
                    hold(&mut r.held, &event.logical_key, event.state.is_pressed());
                }
                if !event.state.is_pressed() {
                    return;
                }
                match self.key(&event.logical_key) {
                    Ok(true) => {
                        el.exit();
                        Ok(())
                    }
                    Ok(false) => Ok(()),
                    Err(e) => Err(e),
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                self.dragging = (state == ElementState::Pressed).then_some(self.cursor);
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor = (position.x, position.y);
                if let (Some((x0, y0)), Some(r)) = (self.dragging, self.running.as_mut()) {
                    let (dx, dy) = ((position.x - x0) as f32, (position.y - y0) as f32);
                    match r.fly.as_mut() {
                        Some(f) => f.look(dx, dy),
                        None => {
                            r.orbit.azimuth -= dx * 0.3;
                            r.orbit.elevation = (r.orbit.elevation + dy * 0.3).clamp(-89.0, 89.0);
                        }
                    }
                    self.dragging = Some((position.x, position.y));
                }
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } => {
                if let Some(r) = self.running.as_mut() {
                    let d = match delta {
                        MouseScrollDelta::LineDelta(_, y) => y,
                        MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                    };
                    match r.fly.as_mut() {
                        Some(f) => f.speed *= 1.25f32.powf(d),
                        None => r.orbit.distance *= 0.9f32.powf(d),
                    }
                }
                Ok(())
            }
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.error = Some(e);
            el.exit();
        }
    }
}
