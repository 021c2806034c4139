//! The per-frame radiosity passes on the GPU: direct exitance per patch
//! (`direct_light.wgsl`), the gather B = S·E (`gather_dense.wgsl` for the f32 reference
//! encoding), and the transfer to the mesh's triangle corners (`corner_interpolate.wgsl`), which
//! writes the mesh renderer's per-corner `indirect` vertex buffer.

use super::compressed_gather::{CompressedGather, DecodePath};
use super::compute;
use super::mesh_renderer::MeshRenderer;
use super::timing::PassTimer;
use super::Gpu;
use crate::error::{Error, Result};
use crate::radiosity::{PatchSet, TransportMatrix};
use crate::render::mesh_reference::FrameSettings;

/// Where the runtime's transport comes from.
pub enum TransportSource<'a> {
    /// The uncompressed `transport.npy` (the reference encoding).
    Dense(&'a TransportMatrix),
    /// The `encode` stage's output, decoded by the given path.
    Compressed(&'a crate::compress::EncodedTransport, DecodePath),
}

impl TransportSource<'_> {
    fn n(&self) -> usize {
        match self {
            TransportSource::Dense(d) => d.n,
            TransportSource::Compressed(t, _) => t.dense.n,
        }
    }
}

/// The gather pass of either source.
enum Gather {
    Dense {
        pipeline: wgpu::ComputePipeline,
        groups: Vec<wgpu::BindGroup>,
    },
    Compressed(CompressedGather),
}

/// GPU buffers and pipelines of the radiosity passes.
pub struct RadiosityRuntime {
    n: u32,
    corners: u32,
    direct: wgpu::ComputePipeline,
    direct_params: wgpu::Buffer,
    direct_group: wgpu::BindGroup,
    gather: Gather,
    transfer: wgpu::ComputePipeline,
    transfer_group: wgpu::BindGroup,
    /// E per patch (vec4).
    pub exitance: wgpu::Buffer,
    /// B_ind per patch (vec4).
    pub indirect: wgpu::Buffer,
}

impl RadiosityRuntime {
    /// Upload the patches and the transport for drawing with `renderer`.
    pub fn new(
        gpu: &Gpu,
        set: &PatchSet,
        transport: TransportSource<'_>,
        renderer: &MeshRenderer,
    ) -> Result<Self> {
        let n = set.patches.len();
        if transport.n() != n {
            return Err(Error::Internal(format!(
                "transport is {0}x{0}, the bake has {n} patches",
                transport.n()
            )));
        }
        if set.corners.len() != renderer.corners() as usize {
            return Err(Error::Internal(format!(
                "transfer lists cover {} corners, the mesh has {}",
                set.corners.len(),
                renderer.corners()
            )));
        }
        let samples: Vec<[f32; 4]> = set
            .samples
            .iter()
            .flat_map(|s| {
                [
                    [s.position[0], s.position[1], s.position[2], 1.0],
                    [s.normal[0], s.normal[1], s.normal[2], 0.0],
                ]
            })
            .collect();
        let albedo: Vec<[f32; 4]> = set
            .patches
            .iter()
            .map(|p| [p.albedo[0], p.albedo[1], p.albedo[2], 0.0])
            .collect();
        let emission: Vec<[f32; 4]> = set
            .patches
            .iter()
            .map(|p| [p.emission[0], p.emission[1], p.emission[2], 0.0])
            .collect();
        let samples = compute::storage(gpu, "samples", &samples);
        let albedo = compute::storage(gpu, "patch albedo", &albedo);
        let emission = compute::storage(gpu, "patch emission", &emission);
        let exitance = compute::output(gpu, "exitance", n as u64 * 16);
        let indirect = compute::output(gpu, "indirect", n as u64 * 16);
        let direct_params = compute::uniform(gpu, "direct params", &[0u32; 4]);

        // The direct kernel shares group 1 (lights + shadow maps) with the mesh renderer, so its
        // layout is explicit.
        let storage = |binding: u32, read_only: bool| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let g0 = gpu
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("direct"),
                entries: &[
                    wgpu::BindGroupLayoutEntry {
                        binding: 0,
                        visibility: wgpu::ShaderStages::COMPUTE,
                        ty: wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Uniform,
                            has_dynamic_offset: false,
                            min_binding_size: None,
                        },
                        count: None,
                    },
                    storage(1, true),
                    storage(2, true),
                    storage(3, true),
                    storage(4, false),
                ],
            });
        let layout = gpu
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("direct"),
                bind_group_layouts: &[Some(&g0), Some(&renderer.group1_layout)],
                immediate_size: 0,
            });
        let module = gpu.shader("direct_light.wgsl")?;
        let direct = gpu
            .device
            .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("direct light"),
                layout: Some(&layout),
                module: &module,
                entry_point: Some("main"),
                compilation_options: Default::default(),
                cache: None,
            });
        let direct_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("direct"),
            layout: &g0,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: direct_params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: samples.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: albedo.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: emission.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: exitance.as_entire_binding(),
                },
            ],
        });

        let gather = match transport {
            TransportSource::Dense(d) => dense_gather(gpu, d, &exitance, &indirect)?,
            TransportSource::Compressed(t, path) => {
                Gather::Compressed(CompressedGather::new(gpu, t, path, &exitance, &indirect)?)
            }
        };

        let transfer = compute::pipeline(gpu, "corner_interpolate.wgsl", "main")?;
        let corners = renderer.corners();
        let tparams = compute::uniform(gpu, "transfer params", &[corners, 0, 0, 0]);
        let offsets = compute::storage(gpu, "transfer offsets", &set.corners.offsets);
        let patches = compute::storage(gpu, "transfer patches", &set.corners.patches);
        let weights = compute::storage(gpu, "transfer weights", &set.corners.values);
        let transfer_group = compute::bind(
            gpu,
            &transfer,
            &[
                tparams.as_entire_binding(),
                offsets.as_entire_binding(),
                patches.as_entire_binding(),
                weights.as_entire_binding(),
                indirect.as_entire_binding(),
                renderer.indirect.as_entire_binding(),
            ],
        );
        Ok(RadiosityRuntime {
            n: n as u32,
            corners,
            direct,
            direct_params,
            direct_group,
            gather,
            transfer,
            transfer_group,
            exitance,
            indirect,
        })
    }

    /// Record direct → gather → corner transfer. Needs the shadow maps of this frame recorded
    /// before (when shadows are on) and `renderer`'s lights set.
    pub fn record(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        renderer: &MeshRenderer,
        s: &FrameSettings,
        spp: u32,
        timer: &mut PassTimer,
    ) {
        let params = [self.n, spp, s.emission_scale.to_bits(), s.flags()];
        gpu.queue
            .write_buffer(&self.direct_params, 0, bytemuck::cast_slice(&params));
        let groups = |count: u32| count.div_ceil(64).max(1);
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("direct"),
                timestamp_writes: timer.compute("direct"),
            });
            pass.set_pipeline(&self.direct);
            pass.set_bind_group(0, &self.direct_group, &[]);
            pass.set_bind_group(1, &renderer.group1, &[]);
            pass.dispatch_workgroups(groups(self.n), 1, 1);
        }
        match &self.gather {
            Gather::Dense { pipeline, groups } => {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("gather"),
                    timestamp_writes: timer.compute("gather"),
                });
                pass.set_pipeline(pipeline);
                for g in groups {
                    pass.set_bind_group(0, g, &[]);
                    pass.dispatch_workgroups(groups_for(self.n), 1, 1);
                }
            }
            Gather::Compressed(c) => c.record(enc, timer),
        }
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("transfer"),
                timestamp_writes: timer.compute("transfer"),
            });
            pass.set_pipeline(&self.transfer);
            pass.set_bind_group(0, &self.transfer_group, &[]);
            pass.dispatch_workgroups(groups(self.corners), 1, 1);
        }
    }
}

fn groups_for(count: u32) -> u32 {
    count.div_ceil(64).max(1)
}

/// The dense f32 gather: one bind group per colour channel.
fn dense_gather(
    gpu: &Gpu,
    d: &TransportMatrix,
    exitance: &wgpu::Buffer,
    indirect: &wgpu::Buffer,
) -> Result<Gather> {
    let n = d.n;
    if !(d.channels == 1 || d.channels == 3) || d.data.len() != d.channels * n * n {
        return Err(Error::Internal(format!(
            "dense transport of {} values is not [1 or 3, {n}, {n}]",
            d.data.len()
        )));
    }
    let per_channel = (n * n * 4) as u64;
    if per_channel > gpu.info.max_storage_buffer_binding_size {
        return Err(Error::limit(format!(
            "an uncompressed {n}x{n} transport channel needs {} MiB, over the adapter's {} MiB storage binding limit; encode it (stage `encode`)",
            per_channel >> 20,
            gpu.info.max_storage_buffer_binding_size >> 20
        )));
    }
    let pipeline = compute::pipeline(gpu, "gather_dense.wgsl", "main")?;
    let matrices: Vec<wgpu::Buffer> = (0..d.channels)
        .map(|c| {
            compute::storage(
                gpu,
                "transport channel",
                &d.data[c * n * n..(c + 1) * n * n],
            )
        })
        .collect();
    let groups = (0..3u32)
        .map(|c| {
            let params = compute::uniform(gpu, "gather params", &[n as u32, c, 0, 0]);
            let m = &matrices[(c as usize).min(d.channels - 1)];
            compute::bind(
                gpu,
                &pipeline,
                &[
                    params.as_entire_binding(),
                    m.as_entire_binding(),
                    exitance.as_entire_binding(),
                    indirect.as_entire_binding(),
                ],
            )
        })
        .collect();
    Ok(Gather::Dense { pipeline, groups })
}
