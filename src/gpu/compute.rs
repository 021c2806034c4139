//! Small helpers for compute kernels: buffers from slices and one-shot dispatches with the
//! kernel's own (automatic) bind-group layout.

use super::Gpu;
use crate::error::Result;
use wgpu::util::DeviceExt;

/// A read-only storage buffer holding `data`.
pub fn storage<T: bytemuck::Pod>(gpu: &Gpu, label: &str, data: &[T]) -> wgpu::Buffer {
    // wgpu rejects zero-sized bindings: keep at least 16 bytes.
    let mut bytes = bytemuck::cast_slice(data).to_vec();
    bytes.resize(bytes.len().max(16), 0);
    gpu.device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: &bytes,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
        })
}

/// A uniform buffer holding `value`.
pub fn uniform<T: bytemuck::Pod>(gpu: &Gpu, label: &str, value: &T) -> wgpu::Buffer {
    gpu.device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytemuck::bytes_of(value),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        })
}

/// A zeroed read-write storage buffer of `bytes` bytes (at least 16).
pub fn output(gpu: &Gpu, label: &str, bytes: u64) -> wgpu::Buffer {
    gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(16).div_ceil(4) * 4,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_SRC
            | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// A bind-group layout entry for a buffer at `binding` (no dynamic offset, any size).
pub fn buffer_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BufferBindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A compute pipeline for `entry` of kernel `shader` with an automatic layout.
pub fn pipeline(gpu: &Gpu, shader: &str, entry: &str) -> Result<wgpu::ComputePipeline> {
    let module = gpu.shader(shader)?;
    Ok(gpu
        .device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(shader),
            layout: None,
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        }))
}

/// Bind `resources` (binding i = resources[i]) to group 0 of `pipeline`.
pub fn bind(
    gpu: &Gpu,
    pipeline: &wgpu::ComputePipeline,
    resources: &[wgpu::BindingResource<'_>],
) -> wgpu::BindGroup {
    bind_group(gpu, pipeline, 0, resources)
}

/// Bind `resources` (binding i = resources[i]) to group `group` of `pipeline`.
pub fn bind_group(
    gpu: &Gpu,
    pipeline: &wgpu::ComputePipeline,
    group: u32,
    resources: &[wgpu::BindingResource<'_>],
) -> wgpu::BindGroup {
    let layout = pipeline.get_bind_group_layout(group);
    let entries: Vec<wgpu::BindGroupEntry> = resources
        .iter()
        .enumerate()
        .map(|(i, r)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: r.clone(),
        })
        .collect();
    gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &layout,
        entries: &entries,
    })
}

/// Dispatch once and wait.
pub fn dispatch(
    gpu: &Gpu,
    pipeline: &wgpu::ComputePipeline,
    group: &wgpu::BindGroup,
    workgroups: [u32; 3],
) {
    dispatch_groups(gpu, pipeline, &[(0, group)], workgroups)
}

/// Dispatch once with bind groups at the given indices, and wait.
pub fn dispatch_groups(
    gpu: &Gpu,
    pipeline: &wgpu::ComputePipeline,
    groups: &[(u32, &wgpu::BindGroup)],
    workgroups: [u32; 3],
) {
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(pipeline);
        for (i, g) in groups {
            pass.set_bind_group(*i, *g, &[]);
        }
        pass.dispatch_workgroups(workgroups[0], workgroups[1], workgroups[2]);
    }
    gpu.queue.submit([enc.finish()]);
    gpu.wait();
}
