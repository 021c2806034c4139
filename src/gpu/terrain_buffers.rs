//! The terrain frame's geometry and storage buffers: group 1 of `terrain_shadow.wgsl` and the
//! display grid (texel centres every `step` texels).

use super::Gpu;
use wgpu::util::DeviceExt;

/// The storage buffers of group 1 (`terrain_shadow.wgsl`).
pub(super) struct TerrainBuffers {
    pub params: wgpu::Buffer,
    pub heights: wgpu::Buffer,
    pub mip_data: wgpu::Buffer,
    pub mip_levels: wgpu::Buffer,
    pub horizon_pair: wgpu::Buffer,
}

impl TerrainBuffers {
    /// Group 1 of a pipeline that includes `terrain_shadow.wgsl`.
    pub fn bind(&self, gpu: &Gpu, layout: &wgpu::BindGroupLayout) -> wgpu::BindGroup {
        let entries: Vec<wgpu::BindGroupEntry> = [
            &self.params,
            &self.heights,
            &self.mip_data,
            &self.mip_levels,
            &self.horizon_pair,
        ]
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("terrain"),
            layout,
            entries: &entries,
        })
    }
}

/// Grid vertices at texel centres every `step` texels (always including the last row and
/// column) and two triangles per cell.
pub(super) fn grid_mesh(gpu: &Gpu, w: u32, h: u32, step: u32) -> (wgpu::Buffer, wgpu::Buffer, u32) {
    let axis = |n: u32| -> Vec<u32> {
        let mut v: Vec<u32> = (0..n).step_by(step as usize).collect();
        if *v.last().unwrap() != n - 1 {
            v.push(n - 1);
        }
        v
    };
    let (xs, ys) = (axis(w), axis(h));
    let verts: Vec<[f32; 2]> = ys
        .iter()
        .flat_map(|&y| xs.iter().map(move |&x| [x as f32 + 0.5, y as f32 + 0.5]))
        .collect();
    let nx = xs.len() as u32;
    let mut idx = Vec::new();
    for j in 0..ys.len() as u32 - 1 {
        for i in 0..nx - 1 {
            let a = j * nx + i;
            idx.extend_from_slice(&[a, a + nx, a + 1, a + 1, a + nx, a + nx + 1]);
        }
    }
    if idx.is_empty() {
        // A one-texel-wide map: a degenerate strip still draws nothing; keep the buffer valid.
        idx.extend_from_slice(&[0, 0, 0]);
    }
    let vb = gpu
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("terrain grid"),
            contents: bytemuck::cast_slice(&verts),
            usage: wgpu::BufferUsages::VERTEX,
        });
    let ib = gpu
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("terrain indices"),
            contents: bytemuck::cast_slice(&idx),
            usage: wgpu::BufferUsages::INDEX,
        });
    (vb, ib, idx.len() as u32)
}
