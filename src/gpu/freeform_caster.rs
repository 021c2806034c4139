//! The freeform caster on wgpu: one `tile` dispatch per level of the screen quadtree, coarse to
//! fine, each reading its parent level's depth ranges, then one `pixel` dispatch
//! (`shaders/freeform.wgsl`; CPU twin `freeform::twin_cast::cast32`).

use super::compute;
use super::readback::read_buffer;
use super::Gpu;
use crate::error::{Error, Result};
use crate::freeform::twin::{GpuField, View32};
use crate::freeform::twin_cast::REFINE_STEPS;

/// Loop iterations after which Mesa's lavapipe ends all loops of a shader invocation
/// (gallivm's `LP_MAX_TGSI_LOOP_ITERATIONS`, Mesa 22.3, counted over every loop together).
pub const LAVAPIPE_LOOPS: u32 = 65_535;
/// Loop iterations one tile pass may spend: three quarters of lavapipe's limit.
const PASS_LOOPS: u32 = 49_152;
/// The most loop iterations per field evaluation on a CPU adapter: one search step and the 26
/// evaluations of a root's refinement must fit in lavapipe's limit.
pub const MAX_CPU_ADAPTER_COST: u32 = LAVAPIPE_LOOPS / (REFINE_STEPS as u32 + 4);
/// Pixel rounds between two reads of the unfinished count, and the most rounds of a frame.
const ROUNDS_PER_CHECK: u32 = 2;
const MAX_ROUNDS: u32 = 256;

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
    pass_loops: u32,
}

/// One cast: per pixel `[t, nx, ny, nz]` (t < 0 where the ray misses), each tile level's depth
/// ranges when asked for, and how the work was split.
pub struct Cast {
    pub hits: Vec<[f32; 4]>,
    /// Coarse to fine, as [`crate::freeform::twin_cast::levels32`] returns them.
    pub levels: Vec<Vec<[f32; 2]>>,
    /// Tile passes recorded, over all levels.
    pub tile_passes: u32,
    /// Rounds of the pixel search until no pixel was left.
    pub pixel_rounds: u32,
}

impl FreeformCaster {
    pub fn new(gpu: &Gpu) -> Result<FreeformCaster> {
        Ok(FreeformCaster {
            tile: compute::pipeline(gpu, "freeform.wgsl", "tile")?,
            pixel: compute::pipeline(gpu, "freeform.wgsl", "pixel")?,
            normals: compute::pipeline(gpu, "freeform.wgsl", "normals")?,
            pass_loops: PASS_LOOPS,
        })
    }

    /// The same caster with `loops` loop iterations per tile pass and pixel round (default
    /// 49,152): smaller budgets split the work into more passes and rounds (tests use it to
    /// check that a search resumed across rounds finds what one uninterrupted search finds).
    pub fn with_pass_loops(mut self, loops: u32) -> FreeformCaster {
        self.pass_loops = loops;
        self
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
        Ok(self
            .cast_levels(gpu, field, view, top_level, refine, prune, false)?
            .hits)
    }

    /// [`Self::cast`], and with `levels` each tile level's depth ranges (coarse to fine, as
    /// [`crate::freeform::twin_cast::levels32`] returns them) read back too.
    #[allow(clippy::too_many_arguments)]
    pub fn cast_levels(
        &self,
        gpu: &Gpu,
        field: &GpuField,
        view: &View32,
        top_level: u32,
        refine: u32,
        prune: bool,
        levels: bool,
    ) -> Result<Cast> {
        let (w, h) = (view.width, view.height);
        let per_cell = field.evaluation_loops() + 1;
        let cpu_adapter = gpu.info.device_type == format!("{:?}", wgpu::DeviceType::Cpu);
        if cpu_adapter && per_cell > MAX_CPU_ADAPTER_COST {
            return Err(Error::knob(format!(
                "this scene's field takes {per_cell} loop iterations per evaluation; {} ({}) ends a shader's loops after {LAVAPIPE_LOOPS} iterations, too few for one step of a pixel's search (at most {MAX_CPU_ADAPTER_COST} per evaluation): cast it on the CPU (--method rmlrc) or on a GPU",
                gpu.info.name,
                gpu.info.driver
            )));
        }
        let cells_per_pass = (self.pass_loops / per_cell).max(1);
        let mut tile_passes = 0;
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
                cells_per_pass as f32,
            ],
            size: [w, h, field.ops.len() as u32, u32::from(prune)],
            level: [0; 4],
        };
        let mut parent = compute::storage(
            gpu,
            "freeform root range",
            &[[view.near_ln, view.far_ln, 0.0, 2.0]],
        );
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
            let out = compute::output(gpu, "freeform ranges", cols as u64 * rows as u64 * 16);
            // The longest walk a tile can have: the whole depth range at this level's cells.
            let cells = ((view.far_ln - view.near_ln) / (view.theta * size as f32)).ceil() as u32 + 2;
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
                for _ in 0..cells.div_ceil(cells_per_pass) {
                    pass.dispatch_workgroups(cols.div_ceil(8), rows.div_ceil(8), 1);
                    tile_passes += 1;
                }
            }
            keep.push((ub, std::mem::replace(&mut parent, out)));
            parent_cols = cols;
            is_top = 0;
        }
        gpu.queue.submit([enc.finish()]);
        // The pixel search, in rounds of at most `steps` steps per pixel, leaving room in
        // lavapipe's loop budget for the refinement of a sign change.
        let steps = (self.pass_loops / per_cell)
            .saturating_sub(REFINE_STEPS as u32 + 2)
            .max(1);
        let search = compute::output(gpu, "freeform search", w as u64 * h as u64 * 16);
        let unfinished = compute::output(gpu, "freeform unfinished", MAX_ROUNDS as u64 * 4);
        let scratch = compute::output(gpu, "freeform unused", 16);
        let resources = |ub: &wgpu::Buffer, pixel: bool| {
            let mut r = vec![
                ub.as_entire_binding(),
                leaves.as_entire_binding(),
                bumps.as_entire_binding(),
                ops.as_entire_binding(),
                parent.as_entire_binding(),
                scratch.as_entire_binding(),
                hits.as_entire_binding(),
            ];
            if pixel {
                r.extend([search.as_entire_binding(), unfinished.as_entire_binding()]);
            }
            compute::bind(gpu, if pixel { &self.pixel } else { &self.normals }, &r)
        };
        let frame = |round: u32| {
            let mut u = base;
            u.depth[3] = steps as f32;
            u.level = [1, round, parent_cols, is_top];
            compute::uniform(gpu, "freeform pixel", &u)
        };
        let mut round = 0;
        let needed = loop {
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            for _ in 0..ROUNDS_PER_CHECK {
                let ub = frame(round);
                let group = resources(&ub, true);
                let mut pass = enc.begin_compute_pass(&Default::default());
                pass.set_pipeline(&self.pixel);
                pass.set_bind_group(0, &group, &[]);
                pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
                round += 1;
            }
            gpu.queue.submit([enc.finish()]);
            let counts = read_buffer(gpu, &unfinished)?;
            let counts: &[u32] = bytemuck::cast_slice(&counts);
            if let Some(r) = counts[..round as usize].iter().position(|&c| c == 0) {
                break r as u32 + 1;
            }
            if round + ROUNDS_PER_CHECK > MAX_ROUNDS {
                return Err(Error::limit(format!(
                    "the freeform pixel search had {} pixels unfinished after {round} rounds of {steps} steps",
                    counts[round as usize - 1]
                )));
            }
        };
        let ub = frame(round);
        let group = resources(&ub, false);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.normals);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(w.div_ceil(8), h.div_ceil(8), 1);
        }
        gpu.queue.submit([enc.finish()]);
        gpu.wait();
        let mut ranges = Vec::new();
        if levels {
            keep.push((ub, parent));
            for (_, buffer) in keep.iter().skip(1) {
                let bytes = read_buffer(gpu, buffer)?;
                let floats: &[f32] = bytemuck::cast_slice(&bytes);
                ranges.push(floats.chunks_exact(4).map(|c| [c[0], c[1]]).collect());
            }
        }
        drop(keep);
        let bytes = read_buffer(gpu, &hits)?;
        let floats: &[f32] = bytemuck::cast_slice(&bytes);
        let hits = floats
            .chunks_exact(4)
            .take((w * h) as usize)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect();
        Ok(Cast {
            hits,
            levels: ranges,
            tile_passes,
            pixel_rounds: needed,
        })
    }
}
