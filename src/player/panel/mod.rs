//! The window's panel (egui): the lights and the sun, exposure, the passes, the camera, frame
//! times and a screenshot button. `Tab` hides it; it is drawn over the window after the frame
//! is blitted, so it never enters the player's target (headless frames, screenshots).
//!
//! - [`show`]: the panel's widgets over a [`PanelView`] of what they edit; it reports what
//!   changed in [`Changes`] for the window to apply (lights re-uploaded, the sun moved, …).
//! - [`layer`]: egui's winit input and wgpu drawing.
//! - [`script`]: scripted input events (`--panel-script`), which drive the panel through egui's
//!   own input path for tests.

pub mod layer;
pub mod script;

use crate::player::Sun;
use crate::render::exposure::{AutoExposure, Exposure};
use crate::render::mesh_reference::FrameSettings;
use crate::scene::{Light, LightKind};
use std::collections::{BTreeMap, VecDeque};

/// What the panel edits this frame.
pub struct PanelView<'a> {
    /// The scene's punctual lights with whether each is on (mesh scenes; None elsewhere).
    pub lights: Option<&'a mut Vec<(Light, bool)>>,
    pub sun: &'a mut Sun,
    pub sun_on: &'a mut bool,
    pub settings: &'a mut FrameSettings,
    pub exposure: &'a mut Exposure,
    /// Terrain toggles are shown for terrain scenes only.
    pub terrain: bool,
    pub fly: bool,
    /// The fly camera's speed (scene units per second), when flying.
    pub fly_speed: Option<&'a mut f32>,
    pub fov: &'a mut f32,
    /// The current view as a `--camera` argument.
    pub camera_arg: String,
    /// Recent frame times (ms), oldest first, and the last frame's GPU time per pass.
    pub frame_ms: &'a VecDeque<f32>,
    pub pass_ms: &'a [(&'static str, f64)],
}

/// What the window must apply after the panel ran.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Changes {
    pub lights: bool,
    pub sun: bool,
    pub toggle_fly: bool,
    pub screenshot: bool,
    pub copy_camera: bool,
}

/// Where each labelled widget was drawn last frame (points), for [`script`].
pub type WidgetRects = BTreeMap<String, egui::Rect>;

/// Draw the panel into the root `ui` and report what changed; `rects` receives the widgets'
/// places.
pub fn show(ui: &mut egui::Ui, v: &mut PanelView, rects: &mut WidgetRects) -> Changes {
    let mut ch = Changes::default();
    egui::Panel::left("relume")
        .default_size(260.0)
        .show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                lights(ui, v, rects, &mut ch);
                ui.separator();
                exposure(ui, v, rects);
                ui.separator();
                passes(ui, v, rects);
                ui.separator();
                camera(ui, v, rects, &mut ch);
                ui.separator();
                timing(ui, v);
                let r = ui.button("Screenshot (F12)");
                ch.screenshot |= track(rects, "Screenshot", &r).clicked();
            });
        });
    ch
}

/// Remember `r`'s place under `label` and hand it back.
fn track<'r>(rects: &mut WidgetRects, label: &str, r: &'r egui::Response) -> &'r egui::Response {
    rects.insert(label.to_string(), r.rect);
    r
}

fn lights(ui: &mut egui::Ui, v: &mut PanelView, rects: &mut WidgetRects, ch: &mut Changes) {
    ui.heading("Lights");
    let r = ui.checkbox(v.sun_on, "Sun");
    ch.sun |= track(rects, "Sun", &r).changed();
    ui.add_enabled_ui(*v.sun_on, |ui| {
        let r = ui.add(egui::Slider::new(&mut v.sun.azimuth_deg, 0.0..=360.0).text("azimuth °"));
        ch.sun |= track(rects, "Sun azimuth", &r).changed();
        let r =
            ui.add(egui::Slider::new(&mut v.sun.elevation_deg, -10.0..=90.0).text("elevation °"));
        ch.sun |= track(rects, "Sun elevation", &r).changed();
        ui.horizontal(|ui| {
            for (label, d) in [("Sun −15°", -15.0), ("Sun +15°", 15.0)] {
                let r = ui.button(label);
                if track(rects, label, &r).clicked() {
                    v.sun.azimuth_deg = (v.sun.azimuth_deg + d).rem_euclid(360.0);
                    ch.sun = true;
                }
            }
        });
    });
    let Some(lights) = v.lights.as_deref_mut() else {
        return;
    };
    for (i, (l, on)) in lights.iter_mut().enumerate() {
        let kind = match l.kind {
            LightKind::Directional => "directional",
            LightKind::Point => "point",
            LightKind::Spot { .. } => "spot",
        };
        let r = ui.checkbox(on, format!("{} ({kind})", l.name));
        ch.lights |= track(rects, &format!("Light {i}"), &r).changed();
        ui.add_enabled_ui(*on, |ui| {
            ui.indent(i, |ui| {
                let unit = if l.kind == LightKind::Directional {
                    "lux"
                } else {
                    "cd"
                };
                let speed = 0.01 * l.intensity.max(0.01);
                let r = ui.add(
                    egui::DragValue::new(&mut l.intensity)
                        .speed(speed)
                        .range(0.0..=f32::MAX)
                        .suffix(format!(" {unit}")),
                );
                ch.lights |= r.changed();
                ch.lights |= ui.color_edit_button_rgb(&mut l.color).changed();
                let (label, vec) = match l.kind {
                    LightKind::Directional => ("direction", &mut l.direction),
                    _ => ("position", &mut l.position),
                };
                ui.horizontal(|ui| {
                    ui.label(label);
                    for c in vec.iter_mut() {
                        ch.lights |= ui.add(egui::DragValue::new(c).speed(0.01)).changed();
                    }
                });
            });
        });
    }
}

fn exposure(ui: &mut egui::Ui, v: &mut PanelView, rects: &mut WidgetRects) {
    ui.heading("Exposure");
    let mut auto = matches!(v.exposure, Exposure::Auto(_));
    let r = ui.checkbox(&mut auto, "Automatic");
    if track(rects, "Automatic exposure", &r).changed() {
        *v.exposure = if auto {
            Exposure::Auto(AutoExposure::default())
        } else {
            Exposure::Fixed(v.settings.exposure)
        };
    }
    match v.exposure {
        Exposure::Auto(a) => {
            ui.add(egui::Slider::new(&mut a.compensation_ev, -4.0..=4.0).text("compensation EV"));
            ui.label(format!("exposure {:.4}", v.settings.exposure));
        }
        Exposure::Fixed(e) => {
            let r = ui.add(
                egui::Slider::new(e, 1e-3..=1e3)
                    .logarithmic(true)
                    .text("exposure"),
            );
            if r.changed() {
                v.settings.exposure = *e;
            }
        }
    }
}

fn passes(ui: &mut egui::Ui, v: &mut PanelView, rects: &mut WidgetRects) {
    ui.heading("Passes");
    let s = &mut *v.settings;
    let mut boxes: Vec<(&mut bool, &str)> = vec![
        (&mut s.direct, "Direct light"),
        (&mut s.indirect, "Indirect light"),
        (&mut s.shadows, "Shadows"),
        (&mut s.emission, "Emission"),
        (&mut s.textures, "Textures"),
    ];
    if v.terrain {
        boxes.extend([
            (&mut s.soft_shadows, "Soft shadows"),
            (&mut s.fog, "Aerial perspective and sky"),
            (&mut s.horizon_shadows, "Shadows from horizon maps"),
            (&mut s.themes, "Thematic textures"),
            (&mut s.theme_animation, "Theme animation"),
        ]);
    }
    for (b, label) in boxes {
        let r = ui.checkbox(b, label);
        track(rects, label, &r);
    }
}

fn camera(ui: &mut egui::Ui, v: &mut PanelView, rects: &mut WidgetRects, ch: &mut Changes) {
    ui.heading("Camera");
    let r = ui.button(if v.fly {
        "Orbit camera (F)"
    } else {
        "Fly camera (F)"
    });
    ch.toggle_fly |= track(rects, "Camera mode", &r).clicked();
    if let Some(speed) = v.fly_speed.as_deref_mut() {
        ui.add(
            egui::Slider::new(speed, 1e-3..=1e4)
                .logarithmic(true)
                .text("speed /s"),
        );
    }
    ui.add(egui::Slider::new(v.fov, 10.0..=120.0).text("field of view °"));
    ui.horizontal(|ui| {
        ui.label(egui::RichText::new(&v.camera_arg).monospace().small());
    });
    let r = ui.button("Copy camera string");
    ch.copy_camera |= track(rects, "Copy camera", &r).clicked();
}

fn timing(ui: &mut egui::Ui, v: &PanelView) {
    ui.heading("Frame time");
    let last = v.frame_ms.back().copied().unwrap_or(0.0);
    let worst = v.frame_ms.iter().copied().fold(1e-3f32, f32::max);
    ui.label(format!(
        "{last:.1} ms (max {worst:.1} ms over {} frames)",
        v.frame_ms.len()
    ));
    let (rect, _) =
        ui.allocate_exact_size(egui::vec2(ui.available_width(), 48.0), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, ui.visuals().extreme_bg_color);
    let n = v.frame_ms.len().max(2) as f32;
    let points: Vec<egui::Pos2> = v
        .frame_ms
        .iter()
        .enumerate()
        .map(|(i, &ms)| {
            egui::pos2(
                rect.left() + rect.width() * i as f32 / (n - 1.0),
                rect.bottom() - rect.height() * (ms / worst).min(1.0),
            )
        })
        .collect();
    painter.add(egui::Shape::line(
        points,
        egui::Stroke::new(1.0, egui::Color32::LIGHT_GREEN),
    ));
    if v.pass_ms.is_empty() {
        ui.small("GPU times per pass: the adapter has no timestamp queries");
    }
    for (name, ms) in v.pass_ms {
        ui.small(format!("{name}: {ms:.2} ms"));
    }
}
