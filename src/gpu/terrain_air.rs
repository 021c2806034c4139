//! The air over a terrain frame (docs/atmosphere.md): the uniform fields of each atmosphere
//! model, Hillaire's tables (built on first use, rebuilt when the sun or the eye's altitude
//! moves), and the sky pass (`vs_sky`/`fs_sky` of `terrain_render.wgsl`, drawn after the
//! terrain where the depth buffer is still at the far plane).
//!
//! The uniform fields themselves (units, the sun on surfaces) are `atmosphere::frame`'s,
//! shared with the freeform renderer.

use super::atmosphere::AtmosphereTables;
use super::render_target::{DEPTH_FORMAT, TARGET_FORMAT};
use super::{compute, Gpu};
pub use crate::atmosphere::frame::{air_frame, AirFrame, SKY};
use crate::atmosphere::twin::AtmosphereGpu;
use crate::atmosphere::Atmosphere;
use crate::error::Result;
use crate::terrain::sun::Sun;

/// The group-3 bindings of the terrain's explicit layout (all three) and of the sky
/// pipeline's automatic one (only what it reads: the parameters and the sky view).
const TERRAIN_USES: &[usize] = &[0, 1, 2];
const SKY_USES: &[usize] = &[0, 1];

/// A bind group of `layout` with bindings `uses` of (parameters, sky view, aerial volume).
fn bind(
    gpu: &Gpu,
    layout: &wgpu::BindGroupLayout,
    uses: &[usize],
    buffers: [&wgpu::Buffer; 3],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = uses
        .iter()
        .map(|&i| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: buffers[i].as_entire_binding(),
        })
        .collect();
    gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("air"),
        layout,
        entries: &entries,
    })
}

/// Hillaire's tables and the sky pass of a terrain renderer.
pub struct TerrainAir {
    pub atmosphere: Atmosphere,
    tables: Option<AtmosphereTables>,
    /// Group 3 of the terrain pipeline and of the sky pipeline.
    pub terrain_group: wgpu::BindGroup,
    sky_group: wgpu::BindGroup,
    sky_frame: wgpu::BindGroup,
    /// The sky pipeline's empty groups 1 and 2.
    sky_empty: [wgpu::BindGroup; 2],
    sky_pipeline: wgpu::RenderPipeline,
}

impl TerrainAir {
    /// The sky pipeline over `module`, group 3 (of layout `terrain`) bound to placeholders
    /// until the first Hillaire frame; `frame` is the terrain's frame uniform.
    pub fn new(
        gpu: &Gpu,
        module: &wgpu::ShaderModule,
        terrain: &wgpu::BindGroupLayout,
        frame: &wgpu::Buffer,
    ) -> TerrainAir {
        let sky_pipeline = gpu
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("terrain sky"),
                layout: None,
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_sky"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: Default::default(),
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(false),
                    depth_compare: Some(wgpu::CompareFunction::LessEqual),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some("fs_sky"),
                    compilation_options: Default::default(),
                    targets: &[Some(TARGET_FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            });
        let placeholder = [
            compute::uniform(gpu, "atmosphere placeholder", &AtmosphereGpu::default()),
            compute::storage(gpu, "sky placeholder", &[0u32; 4]),
            compute::storage(gpu, "aerial placeholder", &[0u32; 4]),
        ];
        let p = [&placeholder[0], &placeholder[1], &placeholder[2]];
        let terrain_group = bind(gpu, terrain, TERRAIN_USES, p);
        let sky_group = bind(gpu, &sky_pipeline.get_bind_group_layout(3), SKY_USES, p);
        let sky_frame = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sky frame"),
            layout: &sky_pipeline.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: frame.as_entire_binding(),
            }],
        });
        let empty = |g: u32| {
            gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &sky_pipeline.get_bind_group_layout(g),
                entries: &[],
            })
        };
        TerrainAir {
            atmosphere: Atmosphere::earth(),
            tables: None,
            sky_empty: [empty(1), empty(2)],
            terrain_group,
            sky_group,
            sky_frame,
            sky_pipeline,
        }
    }

    /// Make Hillaire's tables hold the eye altitude (m), sun and aerial range (m) of this frame:
    /// built on first use (and the bind groups pointed at them), else updated in place when
    /// any differ.
    pub fn prepare_tables(
        &mut self,
        gpu: &Gpu,
        terrain: &wgpu::BindGroupLayout,
        sun: &Sun,
        eye_altitude: f64,
        range: f64,
    ) -> Result<()> {
        // Quantise the eye altitude (1 m) so that a camera gliding sideways rebuilds nothing.
        let p = AtmosphereGpu::new(
            &self.atmosphere,
            eye_altitude.round().max(1.0),
            sun.toward_y_up_f64(),
            range,
        );
        match &mut self.tables {
            Some(t) => t.update(gpu, &p)?,
            None => {
                let t = AtmosphereTables::build(gpu, &p)?;
                let b = [&t.params, &t.sky_view, &t.aerial];
                self.terrain_group = bind(gpu, terrain, TERRAIN_USES, b);
                self.sky_group = bind(
                    gpu,
                    &self.sky_pipeline.get_bind_group_layout(3),
                    SKY_USES,
                    b,
                );
                self.tables = Some(t);
            }
        }
        Ok(())
    }

    /// Draw the sky into `pass` (after the terrain).
    pub fn record_sky(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_pipeline(&self.sky_pipeline);
        pass.set_bind_group(0, &self.sky_frame, &[]);
        pass.set_bind_group(1, &self.sky_empty[0], &[]);
        pass.set_bind_group(2, &self.sky_empty[1], &[]);
        pass.set_bind_group(3, &self.sky_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
