//! Shading of a freeform cast on wgpu (`shaders/freeform_shade.wgsl`; CPU twin
//! `render::freeform_shade::shade32`): from the cast's hits and shadow state into an RGBA8
//! storage target; the air (aerial perspective and sky) when the scene has one, Hillaire's
//! tables bound as group 3.

use super::atmosphere::AtmosphereTables;
use super::compute;
use super::freeform_caster::GpuCast;
use super::themes::ThemeGpu;
use super::timing::PassTimer;
use super::Gpu;
use crate::atmosphere::frame::AirFrame;
use crate::atmosphere::twin::AtmosphereGpu;
use crate::error::Result;
use crate::freeform::twin::View32;
use crate::render::freeform_shade::Shading;

/// The kernel's `ShadeFrame` uniform.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ShadeFrameU {
    pub forward: [f32; 4],
    pub right: [f32; 4],
    pub up: [f32; 4],
    pub sun: [f32; 4],
    pub background: [f32; 4],
    pub size: [u32; 4],
    pub eye: [f32; 4],
    pub projection: [f32; 4],
    pub air: [u32; 4],
    pub air_scale: [f32; 4],
    pub sun_light: [f32; 4],
    pub fog_ext: [f32; 4],
    pub fog_rayleigh: [f32; 4],
    pub fog_mie: [f32; 4],
    pub fog_sun: [f32; 4],
}

pub struct FreeformShader {
    pipeline: wgpu::ComputePipeline,
    /// The scene's themes (a placeholder until [`FreeformShader::set_themes`]) and how they
    /// are laid on it (kind 0 = none).
    themes: ThemeGpu,
    theme_group: wgpu::BindGroup,
    empty_group: wgpu::BindGroup,
    projection: (u32, [f32; 4]),
    /// Hillaire's tables (built on the first Hillaire frame) and group 3 (placeholders
    /// until then).
    tables: Option<AtmosphereTables>,
    air_group: wgpu::BindGroup,
}

/// Group 3 of `pipeline` over (parameters, sky view, aerial volume).
fn air_bind(gpu: &Gpu, pipeline: &wgpu::ComputePipeline, b: [&wgpu::Buffer; 3]) -> wgpu::BindGroup {
    compute::bind_group(gpu, pipeline, 3, &b.map(|x| x.as_entire_binding()))
}

impl FreeformShader {
    pub fn new(gpu: &Gpu) -> Result<FreeformShader> {
        let pipeline = compute::pipeline(gpu, "freeform_shade.wgsl", "shade")?;
        let themes = ThemeGpu::upload(gpu, &crate::theme::ThemeSet::placeholder());
        let theme_group = themes.bind(gpu, &pipeline.get_bind_group_layout(2));
        let empty_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &pipeline.get_bind_group_layout(1),
            entries: &[],
        });
        let placeholder = [
            compute::uniform(gpu, "atmosphere placeholder", &AtmosphereGpu::default()),
            compute::storage(gpu, "sky placeholder", &[0u32; 4]),
            compute::storage(gpu, "aerial placeholder", &[0u32; 4]),
        ];
        let air_group = air_bind(
            gpu,
            &pipeline,
            [&placeholder[0], &placeholder[1], &placeholder[2]],
        );
        Ok(FreeformShader {
            pipeline,
            themes,
            theme_group,
            empty_group,
            projection: (0, [0.0; 4]),
            tables: None,
            air_group,
        })
    }

    /// Make Hillaire's tables hold `p` (eye altitude, sun, range): built on first use, else
    /// updated in place.
    pub fn prepare_air_tables(&mut self, gpu: &Gpu, p: &AtmosphereGpu) -> Result<()> {
        match &mut self.tables {
            Some(t) => t.update(gpu, p)?,
            None => {
                let t = AtmosphereTables::build(gpu, p)?;
                self.air_group = air_bind(gpu, &self.pipeline, [&t.params, &t.sky_view, &t.aerial]);
                self.tables = Some(t);
            }
        }
        Ok(())
    }

    /// Texture every surface with `set`, laid on the scene by `projection` (kind 1 planar /
    /// 2 spherical and its numbers, `ThemeProjection::packed`), animation frame `frame`.
    pub fn set_themes(
        &mut self,
        gpu: &Gpu,
        set: &crate::theme::ThemeSet,
        projection: (u32, [f32; 4]),
        frame: u32,
    ) {
        self.themes = ThemeGpu::upload(gpu, set);
        self.themes.set_shift(gpu, set.shift(frame));
        self.theme_group = self
            .themes
            .bind(gpu, &self.pipeline.get_bind_group_layout(2));
        self.projection = projection;
    }

    /// Move the theme borders to `shift` (`ThemeSet::shift`).
    pub fn set_theme_shift(&mut self, gpu: &Gpu, shift: [f32; 2]) {
        self.themes.set_shift(gpu, shift);
    }

    /// Shade `cast` (of `view`, its eye at `eye`) into `target` (a storage-capable RGBA8 view
    /// of the view's size); `themed` applies the themes set with [`Self::set_themes`]; `air`
    /// the frame's air and the scene's km per unit (Hillaire's model needs
    /// [`Self::prepare_air_tables`] first); `timer` times the pass as "shade".
    #[allow(clippy::too_many_arguments)]
    pub fn shade(
        &self,
        gpu: &Gpu,
        cast: &GpuCast,
        view: &View32,
        eye: [f32; 3],
        s: &Shading,
        themed: bool,
        air: Option<(&AirFrame, f32)>,
        target: &wgpu::TextureView,
        timer: Option<&mut PassTimer>,
    ) {
        let kind = if themed { self.projection.0 } else { 0 };
        let none = AirFrame {
            sun_light: [1.0, 1.0, 1.0, 0.0],
            ..AirFrame::default()
        };
        let (a, km) = air.unwrap_or((&none, 0.0));
        let model = if a.model == 3 && self.tables.is_none() {
            0
        } else {
            a.model
        };
        let u = ShadeFrameU {
            forward: [
                view.forward[0],
                view.forward[1],
                view.forward[2],
                view.tan_x,
            ],
            right: [view.right[0], view.right[1], view.right[2], view.tan_y],
            up: [view.up[0], view.up[1], view.up[2], s.exposure],
            sun: [s.sun[0], s.sun[1], s.sun[2], s.ambient],
            background: [s.background[0], s.background[1], s.background[2], 0.0],
            size: [view.width, view.height, u32::from(s.shadows), kind],
            eye: [eye[0], eye[1], eye[2], 2.0 * view.tan_x / view.width as f32],
            projection: self.projection.1,
            air: [model, 0, 0, 0],
            air_scale: [km, 0.0, 0.0, 0.0],
            sun_light: a.sun_light,
            fog_ext: a.fog_ext,
            fog_rayleigh: a.fog_rayleigh,
            fog_mie: a.fog_mie,
            fog_sun: a.fog_sun,
        };
        let ub = compute::uniform(gpu, "freeform shade", &u);
        let group = compute::bind(
            gpu,
            &self.pipeline,
            &[
                ub.as_entire_binding(),
                cast.leaves.as_entire_binding(),
                cast.hits.as_entire_binding(),
                cast.state.as_entire_binding(),
                wgpu::BindingResource::TextureView(target),
            ],
        );
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        let mut timer = timer;
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("freeform shade"),
                timestamp_writes: timer.as_mut().and_then(|t| t.compute("shade")),
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.set_bind_group(1, &self.empty_group, &[]);
            pass.set_bind_group(2, &self.theme_group, &[]);
            pass.set_bind_group(3, &self.air_group, &[]);
            pass.dispatch_workgroups(view.width.div_ceil(8), view.height.div_ceil(8), 1);
        }
        if let Some(t) = &timer {
            t.resolve(&mut enc);
        }
        gpu.queue.submit([enc.finish()]);
        gpu.wait();
    }
}
