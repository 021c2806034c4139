//! The freeform caster on wgpu: one `tile` dispatch per level of the screen quadtree, coarse to
//! fine, each reading its parent level's depth ranges, then one `pixel` dispatch
//! (`shaders/freeform.wgsl`; CPU twin `freeform::twin_cast::cast32`).

use super::compute;
use super::readback::read_buffer;
use super::Gpu;
use crate::error::Result;
use crate::freeform::twin::{GpuField, View32};

/// The kernel's `Frame` uniform (one per level).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameU {
    pub forward: [f32; 4],
    pub right: [f32; 4],
    pub up: [f32; 4],
    pub depth: [f32; 4],
    pub size: [u32; 4],
    pub level: [u32; 4],
}

/// Compiled kernels of the freeform caster.
pub struct FreeformCaster {
    tile: wgpu::ComputePipeline,
    pixel: wgpu::ComputePipeline,
    normals: wgpu::ComputePipeline,
}

impl FreeformCaster {
    pub fn new(gpu: &Gpu) -> Result<FreeformCaster> {
        Ok(FreeformCaster {
            tile: compute::pipeline(gpu, "freeform.wgsl", "tile")?,
            pixel: compute::pipeline(gpu, "freeform.wgsl", "pixel")?,
            normals: compute::pipeline(gpu, "freeform.wgsl", "normals")?,
        })
    }

    /// Cast every pixel: per pixel `[t, nx, ny, nz]`, t < 0 where the ray misses. All levels are
    /// recorded in one command buffer and submitted once.
    pub fn cast(
        &self,
        gpu: &Gpu,
        field: &GpuField,
        view: &View32,
        top_level: u32,
        refine: u32,
        prune: bool,
    ) -> Result<Vec<[f32; 4]>> {
        let (w, h) = (view.width, view.height);
        let leaves = compute::storage(gpu, "freeform leaves", &field.leaves);
        // A binding holds at least one element; a scene without bumps never reads it.
        let one = [crate::freeform::twin::GpuBump::default()];
        let bumps = compute::storage(
            gpu,
            "freeform bumps",
            if field.bumps.is_empty() {
                &one
            } else {
                &field.bumps
            },
        );
        let ops = compute::storage(gpu, "freeform ops", &field.ops);
        let hits = compute::output(gpu, "freeform hits", w as u64 * h as u64 * 16);
        let base = FrameU {
            forward: [
                view.forward[0],
                view.forward[1],
                view.forward[2],
                view.tan_x,
            ],
            right: [view.right[0], view.right[1], view.right[2], view.tan_y],
            up: [view.up[0], view.up[1], view.up[2], view.theta],
            depth: [
                view.near_ln,
                view.far_ln,
                view.theta / (1u32 << refine) as f32,
                0.0,
            ],
            size: [w, h, field.ops.len() as u32, u32::from(prune)],
            level: [0; 4],
        };
        let mut parent =
            compute::storage(gpu, "freeform root range", &[[view.near_ln, view.far_ln]]);
        let mut parent_cols = 1u32;
        let mut is_top = 1u32;
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        let mut keep = Vec::new();
        for level in (1..=top_level).rev() {
            let size = 1u32 << level;
            let (cols, rows) = (w.div_ceil(size), h.div_ceil(size));
            let mut u = base;
            u.level = [size, cols, parent_cols, is_top];
            let ub = compute::uniform(gpu, "freeform level", &u);
            let out = compute::output(gpu, "freeform ranges", cols as u64 * rows as u64 * 8);
            let group = compute::bind(
                gpu,
                &self.tile,
                &[
                    ub.as_entire_binding(),
                    leaves.as_entire_binding(),
                    bumps.as_entire_binding(),
                    ops.as_entire_binding(),
                    parent.as_entire_binding(),
                    out.as_entire_binding(),
                    hits.as_entire_binding(),
                ],
            );
            {
                let mut pass = enc.begin_compute_pass(&Default::default());
                pass.set_pipeline(&self.tile);
                pass.set_bind_group(0, &group, &[]);
                pass.dispatch_workgroups(cols.div_ceil(8), rows.div_ceil(8), 1);
            }
            keep.push((ub, std::mem::replace(&mut parent, out)));
            parent_cols = cols;
            is_top = 0;
        }
        let mut u = base;
        u.level = [1, w, parent_cols, is_top];
        let ub = compute::uniform(gpu, "freeform pixel", &u);
        let scratch = compute::output(gpu, "freeform unused", 16);
        for pipeline in [&self.pixel, &self.normals] {
            let group = compute::bind(
                gpu,
                pipeline,
                &[
                    ub.as_entire_binding(),
                    leaves.as_entire_binding(),
                    bumps.as_entire_binding(),
                    ops.as_entire_binding(),
                    parent.as_entire_binding(),
                    scratch.as_entire_binding(),
                    hits.as_entire_binding(),
                ],
            );
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
        }
        gpu.queue.submit([enc.finish()]);
        gpu.wait();
        drop(keep);
        let bytes = read_buffer(gpu, &hits)?;
        let floats: &[f32] = bytemuck::cast_slice(&bytes);
        Ok(floats
            .chunks_exact(4)
            .take((w * h) as usize)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect())
    }
}
