//! Freeform scenes at runtime (`relume-player scenes/freeform/X.ron`): the scene's field cast on
//! the GPU each frame by the multilevel caster (`gpu::freeform_caster`), sun shadows by the
//! same search toward the sun, and the shading kernel (`gpu::freeform_shader`) into the target.
//! Thematic textures over every surface when the scene names a theme set (docs/themes.md); the
//! air (aerial perspective and sky by the frame's atmosphere model) when it has `air`.
//! The sun and the camera move freely; nothing is baked.

use crate::atmosphere::frame::{air_frame, AirFrame};
use crate::atmosphere::twin::AtmosphereGpu;
use crate::atmosphere::{Atmosphere, Model};
use crate::error::{Error, Result};
use crate::freeform::rmlrc::{camera_outside, RmlrcParams};
use crate::freeform::shade::sun_direction;
use crate::freeform::twin::{GpuField, View32};
use crate::freeform::{Bound, Field, View};
use crate::gpu::freeform_caster::{FreeformCaster, ShadowSun};
use crate::gpu::freeform_shader::FreeformShader;
use crate::gpu::render_target::RenderTarget;
use crate::gpu::timing::PassTimer;
use crate::gpu::Gpu;
use crate::render::camera::Camera;
use crate::render::freeform_image::DEFAULT_SUN;
use crate::render::freeform_shade::{air_placement, Shading};
use crate::render::mesh_reference::FrameSettings;
use crate::scene::freeform::{FreeformCamera, FreeformScene, SceneAir};
use crate::terrain::sun::Sun;
use glam::Vec3;
use std::path::Path;

/// A loaded freeform scene.
pub struct FreeformPlayer {
    pub scene: FreeformScene,
    pub field: Field,
    caster: FreeformCaster,
    shader: FreeformShader,
    pub target: RenderTarget,
    sun: Sun,
    params: RmlrcParams,
    morph: f64,
    /// The scene's theme set, when it names one.
    pub themes: Option<crate::theme::ThemeSet>,
}

impl FreeformPlayer {
    /// Read the scene at `path` (and the height maps it names) for a `width`×`height` target.
    pub fn load(gpu: &Gpu, path: &Path, width: u32, height: u32) -> Result<FreeformPlayer> {
        let scene = crate::load::freeform_scene(path)?;
        let field = Field::compile(&scene.shape).map_err(|e| Error::input(path, e))?;
        // Refuse what the kernel cannot evaluate before any frame (deep CSG, huge textures).
        GpuField::upload(&field, [0.0; 3]).map_err(|e| Error::input(path, e))?;
        let sun = scene.sun.map_or(DEFAULT_SUN, |s| Sun {
            azimuth_deg: s.azimuth,
            elevation_deg: s.elevation,
        });
        let mut shader = FreeformShader::new(gpu)?;
        let themes = crate::load::freeform_themes(path, &scene)?;
        if let (Some(set), Some(t)) = (&themes, &scene.themes) {
            shader.set_themes(gpu, set, t.projection.packed(), 0);
        }
        Ok(FreeformPlayer {
            caster: FreeformCaster::new(gpu)?,
            shader,
            themes,
            target: RenderTarget::new_storage(gpu, width, height),
            scene,
            field,
            sun,
            params: RmlrcParams::default(),
            morph: 0.0,
        })
    }

    /// The scene's camera, or one looking at the origin from (4, 3, 5).
    pub fn default_camera(&self) -> Camera {
        let c = self.scene.camera.clone().unwrap_or(FreeformCamera {
            eye: [4.0, 3.0, 5.0],
            target: [0.0; 3],
            fov: 45.0,
            near: None,
            far: None,
        });
        let view = View::new(&c, 1, 1);
        let v = |p: [f64; 3]| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
        Camera {
            eye: v(c.eye),
            target: v(c.target),
            up: Vec3::Y,
            fov_y_deg: c.fov as f32,
            near: view.near as f32,
            far: view.far as f32,
        }
    }

    /// Set the sun (default: the scene's, else azimuth 135°, elevation 35°).
    pub fn set_sun(&mut self, sun: Option<Sun>) {
        if let Some(s) = sun {
            self.sun = s;
        }
    }

    /// Move the theme borders to animation frame `frame`.
    pub fn set_theme_frame(&mut self, gpu: &Gpu, frame: u32) {
        if let Some(set) = &self.themes {
            self.shader.set_theme_shift(gpu, set.shift(frame));
        }
    }

    /// Morph the shape textures that have a second grid to parameter `s` ∈ [0, 1] (the
    /// headless player sweeps 0 → 1 over its `--frames`).
    pub fn set_morph(&mut self, s: f64) {
        if s != self.morph && self.field.textures.iter().any(|t| t.morphs()) {
            self.field.set_morph(s);
            self.morph = s;
        }
    }

    /// Cast, shadow and shade one frame into the target.
    pub fn render(
        &mut self,
        gpu: &Gpu,
        camera: &Camera,
        s: &FrameSettings,
        timer: &mut PassTimer,
    ) -> Result<()> {
        timer.reset();
        let d = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
        let cam = FreeformCamera {
            eye: d(camera.eye),
            target: d(camera.target),
            fov: camera.fov_y_deg as f64,
            near: Some(camera.near as f64),
            far: Some(camera.far as f64),
        };
        let view = View::new(&cam, self.target.width, self.target.height);
        let v32 = View32::of(&view);
        let gf = GpuField::upload(&self.field, view.eye)?;
        let prune = camera_outside(&self.field, &view, Bound::Affine);
        let l = sun_direction(self.sun.azimuth_deg, self.sun.elevation_deg).map(|v| v as f32);
        let sun = s.shadows.then_some(ShadowSun {
            direction: l,
            scale: (view.far * view.near).sqrt() as f32,
        });
        let p = &self.params;
        let run = self
            .caster
            .run(gpu, &gf, &v32, p.top_level, p.refine, prune, sun)?;
        let shading = Shading {
            sun: l,
            ambient: self.scene.ambient as f32,
            background: self.scene.background.map(|v| v as f32),
            exposure: s.exposure,
            shadows: s.shadows,
        };
        let eye = view.eye.map(|v| v as f32);
        let air = match self.scene.air {
            Some(a) => Some(self.air(gpu, &a, &view, l, s)?),
            None => None,
        };
        self.shader.shade(
            gpu,
            &run,
            &v32,
            eye,
            &shading,
            s.themes && self.themes.is_some(),
            air.as_ref().map(|(f, km)| (f, *km)),
            &self.target.view,
            Some(timer),
        );
        Ok(())
    }

    /// The air of this frame over a scene placed by `a` (the model: `s.atmosphere`, none when
    /// `s.fog` is off), with Hillaire's tables prepared for the eye's altitude and the sun.
    fn air(
        &mut self,
        gpu: &Gpu,
        a: &SceneAir,
        view: &View,
        sun: [f32; 3],
        s: &FrameSettings,
    ) -> Result<(AirFrame, f32)> {
        let atm = Atmosphere::earth();
        let model = if s.fog { s.atmosphere } else { Model::None };
        let (eye_altitude, sun, range) = air_placement(a, view.eye[1], view.far, sun, &atm);
        let frame = air_frame(&atm, model, sun, eye_altitude, 0.0, 1.0);
        if model == Model::Hillaire {
            let p = AtmosphereGpu::new(&atm, eye_altitude, sun, range);
            self.shader.prepare_air_tables(gpu, &p)?;
        }
        Ok((frame, (a.metres_per_unit / 1000.0) as f32))
    }

    /// Resize the target.
    pub fn resize(&mut self, gpu: &Gpu, width: u32, height: u32) {
        self.target = RenderTarget::new_storage(gpu, width, height);
    }
}
