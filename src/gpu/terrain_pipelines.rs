//! The terrain frame's render pipelines: one explicit layout (groups 0 frame, 1 terrain
//! buffers, 2 themes, 3 the air's tables) shared by one pipeline per combination of the
//! `THEMES` and `HILLAIRE` override constants of `terrain_render.wgsl`, made on first use.
//!
//! Why variants: a software rasteriser (Mesa llvmpipe, lavapipe) runs both sides of a branch
//! under a lane mask, so code a frame does not use still costs — the theme lookup and the
//! aerial-perspective volume tripled a plain 1080p frame (measured: 971 ms against 375 ms with
//! the theme code compiled out). Constant conditions fold away at pipeline creation; a real
//! GPU skips a uniform branch either way.

use super::atmosphere::AtmosphereTables;
use super::compute::buffer_entry;
use super::render_target::{DEPTH_FORMAT, TARGET_FORMAT};
use super::Gpu;
use crate::error::Result;

/// Layouts, the shader module and the pipeline variants.
pub(super) struct TerrainPipelines {
    /// The bind-group layouts of groups 0–3.
    pub layouts: [wgpu::BindGroupLayout; 4],
    layout: wgpu::PipelineLayout,
    pub module: wgpu::ShaderModule,
    variants: [Option<wgpu::RenderPipeline>; 4],
}

impl TerrainPipelines {
    pub fn new(gpu: &Gpu) -> Result<TerrainPipelines> {
        use wgpu::BufferBindingType::{Storage, Uniform};
        use wgpu::ShaderStages as S;
        let ro = Storage { read_only: true };
        let both = S::VERTEX_FRAGMENT;
        let layout = |label: &str, entries: &[wgpu::BindGroupLayoutEntry]| {
            gpu.device
                .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some(label),
                    entries,
                })
        };
        let mut terrain = vec![buffer_entry(0, both, Uniform)];
        terrain.extend((1..5).map(|b| buffer_entry(b, both, ro)));
        let layouts = [
            layout("terrain frame", &[buffer_entry(0, both, Uniform)]),
            layout("terrain buffers", &terrain),
            layout(
                "themes",
                &[
                    buffer_entry(0, S::FRAGMENT, Uniform),
                    buffer_entry(1, S::FRAGMENT, ro),
                ],
            ),
            layout("air", &AtmosphereTables::layout_entries(S::FRAGMENT)),
        ];
        let pipeline_layout = gpu
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("terrain"),
                bind_group_layouts: &[
                    Some(&layouts[0]),
                    Some(&layouts[1]),
                    Some(&layouts[2]),
                    Some(&layouts[3]),
                ],
                immediate_size: 0,
            });
        Ok(TerrainPipelines {
            layouts,
            layout: pipeline_layout,
            module: gpu.shader("terrain_render.wgsl")?,
            variants: [None, None, None, None],
        })
    }

    /// The pipeline with the theme lookup and Hillaire's aerial perspective compiled in or out.
    pub fn get(&mut self, gpu: &Gpu, themes: bool, hillaire: bool) -> &wgpu::RenderPipeline {
        let k = usize::from(themes) | usize::from(hillaire) << 1;
        let (module, layout) = (&self.module, &self.layout);
        self.variants[k].get_or_insert_with(|| {
            let constants = [
                ("THEMES", f64::from(u8::from(themes))),
                ("HILLAIRE", f64::from(u8::from(hillaire))),
            ];
            let options = wgpu::PipelineCompilationOptions {
                constants: &constants,
                ..Default::default()
            };
            gpu.device
                .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("terrain"),
                    layout: Some(layout),
                    vertex: wgpu::VertexState {
                        module,
                        entry_point: Some("vs_main"),
                        compilation_options: options.clone(),
                        buffers: &[Some(wgpu::VertexBufferLayout {
                            array_stride: 8,
                            step_mode: wgpu::VertexStepMode::Vertex,
                            attributes: &[wgpu::VertexAttribute {
                                format: wgpu::VertexFormat::Float32x2,
                                offset: 0,
                                shader_location: 0,
                            }],
                        })],
                    },
                    primitive: wgpu::PrimitiveState {
                        cull_mode: None,
                        ..Default::default()
                    },
                    depth_stencil: Some(wgpu::DepthStencilState {
                        format: DEPTH_FORMAT,
                        depth_write_enabled: Some(true),
                        depth_compare: Some(wgpu::CompareFunction::Less),
                        stencil: Default::default(),
                        bias: Default::default(),
                    }),
                    multisample: Default::default(),
                    fragment: Some(wgpu::FragmentState {
                        module,
                        entry_point: Some("fs_main"),
                        compilation_options: options,
                        targets: &[Some(TARGET_FORMAT.into())],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
        })
    }
}
