//! The freeform caster on wgpu (`shaders/freeform.wgsl`; CPU twin `freeform::twin_cast`):
//! per level of the screen quadtree, coarse to fine, `tile` passes that each walk a bounded
//! number of depth cells; then rounds of the resumable per-pixel search (`pixel`) until no
//! pixel is left; `normals`; and, for shadows, rounds of the same search toward the sun
//! (`shadow`).
//!
//! Why passes and rounds: Mesa's lavapipe ends every loop of a shader invocation once the
//! invocation has run 65,535 loop iterations in all (gallivm's `LP_MAX_TGSI_LOOP_ITERATIONS`),
//! silently — at 256 perturbations and 640×480 a one-dispatch caster returned no hits at all.
//! Each pass or round here stays within three quarters of that; on a GPU the same split keeps a
//! frame's dispatches short for the driver's watchdog.

use super::compute;
use super::readback::read_buffer;
use super::Gpu;
use crate::error::{Error, Result};
use crate::freeform::twin::{GpuField, View32};
use crate::freeform::twin_cast::REFINE_STEPS;

/// Loop iterations after which Mesa's lavapipe ends all loops of a shader invocation
/// (gallivm's `LP_MAX_TGSI_LOOP_ITERATIONS`, Mesa 22.3, counted over every loop together).
pub const LAVAPIPE_LOOPS: u32 = 65_535;
/// Loop iterations one tile pass or search round may spend: three quarters of that limit.
const PASS_LOOPS: u32 = 49_152;
/// The most loop iterations per field evaluation on a CPU adapter: one search step and the 26
/// evaluations of a root's refinement must fit in lavapipe's limit.
pub const MAX_CPU_ADAPTER_COST: u32 = LAVAPIPE_LOOPS / (REFINE_STEPS as u32 + 4);
/// Search rounds between two reads of the unfinished count, and the most rounds of a search.
const ROUNDS_PER_CHECK: u32 = 2;
const MAX_ROUNDS: u32 = 256;

/// The kernel's `Frame` uniform (one per pass).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameU {
    pub forward: [f32; 4],
    pub right: [f32; 4],
    pub up: [f32; 4],
    pub depth: [f32; 4],
    pub size: [u32; 4],
    pub level: [u32; 4],
    pub sun: [f32; 4],
}

/// Compiled kernels of the freeform caster.
pub struct FreeformCaster {
    tile: wgpu::ComputePipeline,
    pixel: wgpu::ComputePipeline,
    normals: wgpu::ComputePipeline,
    shadow: wgpu::ComputePipeline,
    pass_loops: u32,
}

/// The sun for the shadow pass: unit direction toward it and the scene's scale (the shadow
/// ray leaves the surface by `1e-5·max(t, scale·1e-3)`, as the CPU caster's does).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowSun {
    pub direction: [f32; 3],
    pub scale: f32,
}

/// A cast left on the GPU: per pixel `[t, nx, ny, nz]` in `hits` (t < 0: miss) and
/// `(status, shadowed, leaf, 0)` in `state`; the tile levels' range buffers; how the work was
/// split.
pub struct GpuCast {
    pub hits: wgpu::Buffer,
    pub state: wgpu::Buffer,
    pub leaves: wgpu::Buffer,
    levels: Vec<wgpu::Buffer>,
    pub tile_passes: u32,
    pub pixel_rounds: u32,
    pub shadow_rounds: u32,
}

/// A cast read back.
pub struct Cast {
    pub hits: Vec<[f32; 4]>,
    /// Coarse to fine, as [`crate::freeform::twin_cast::levels32`] returns them (when asked).
    pub levels: Vec<Vec<[f32; 2]>>,
    /// Per pixel (status, shadowed, leaf, 0); shadowed is 0 without a shadow pass.
    pub state: Vec<[f32; 4]>,
    pub tile_passes: u32,
    pub pixel_rounds: u32,
    pub shadow_rounds: u32,
}

fn vec4s(bytes: &[u8]) -> Vec<[f32; 4]> {
    let floats: &[f32] = bytemuck::cast_slice(bytes);
    floats
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect()
}

impl FreeformCaster {
    pub fn new(gpu: &Gpu) -> Result<FreeformCaster> {
        let p = |entry| compute::pipeline(gpu, "freeform.wgsl", entry);
        Ok(FreeformCaster {
            tile: p("tile")?,
            pixel: p("pixel")?,
            normals: p("normals")?,
            shadow: p("shadow")?,
            pass_loops: PASS_LOOPS,
        })
    }

    /// The same caster with `loops` loop iterations per tile pass and search round (default
    /// 49,152): smaller budgets split the work into more passes and rounds (tests use it to
    /// check that a search resumed across rounds finds what one uninterrupted search finds).
    pub fn with_pass_loops(mut self, loops: u32) -> FreeformCaster {
        self.pass_loops = loops;
        self
    }

    /// Cast every pixel: per pixel `[t, nx, ny, nz]`, t < 0 where the ray misses.
    pub fn cast(
        &self,
        gpu: &Gpu,
        field: &GpuField,
        view: &View32,
        top_level: u32,
        refine: u32,
        prune: bool,
    ) -> Result<Vec<[f32; 4]>> {
        let run = self.run(gpu, field, view, top_level, refine, prune, None)?;
        Ok(self.read(gpu, &run, view, false)?.hits)
    }

    /// [`Self::run`] and everything read back (the tile levels' ranges with `levels`).
    #[allow(clippy::too_many_arguments)]
    pub fn cast_levels(
        &self,
        gpu: &Gpu,
        field: &GpuField,
        view: &View32,
        top_level: u32,
        refine: u32,
        prune: bool,
        sun: Option<ShadowSun>,
        levels: bool,
    ) -> Result<Cast> {
        let run = self.run(gpu, field, view, top_level, refine, prune, sun)?;
        self.read(gpu, &run, view, levels)
    }

    /// Read a cast back (the tile levels' ranges too with `levels`).
    pub fn read(&self, gpu: &Gpu, run: &GpuCast, view: &View32, levels: bool) -> Result<Cast> {
        let n = (view.width * view.height) as usize;
        let mut ranges = Vec::new();
        if levels {
            for buffer in &run.levels {
                let v = vec4s(&read_buffer(gpu, buffer)?);
                ranges.push(v.iter().map(|c| [c[0], c[1]]).collect());
            }
        }
        let mut hits = vec4s(&read_buffer(gpu, &run.hits)?);
        let mut state = vec4s(&read_buffer(gpu, &run.state)?);
        hits.truncate(n);
        state.truncate(n);
        Ok(Cast {
            hits,
            levels: ranges,
            state,
            tile_passes: run.tile_passes,
            pixel_rounds: run.pixel_rounds,
            shadow_rounds: run.shadow_rounds,
        })
    }

    /// Run the whole cast (and the shadow search toward `sun`), leaving the results on the GPU.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &self,
        gpu: &Gpu,
        field: &GpuField,
        view: &View32,
        top_level: u32,
        refine: u32,
        prune: bool,
        sun: Option<ShadowSun>,
    ) -> Result<GpuCast> {
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
        // The program, then the shape-texture records it names.
        let program: Vec<u32> = field.ops.iter().chain(&field.textures).copied().collect();
        let ops = compute::storage(gpu, "freeform ops", &program);
        let pixels = w as u64 * h as u64;
        let hits = compute::output(gpu, "freeform hits", pixels * 16);
        let state = compute::output(gpu, "freeform shading state", pixels * 16);
        let search = compute::output(gpu, "freeform search", pixels * 16);
        let sun_u = sun.map_or([0.0; 4], |s| {
            [s.direction[0], s.direction[1], s.direction[2], s.scale]
        });
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
            sun: sun_u,
        };
        let bind = |pipeline: &wgpu::ComputePipeline,
                    ub: &wgpu::Buffer,
                    parent: &wgpu::Buffer,
                    out: &wgpu::Buffer,
                    searching: bool,
                    counts: Option<&wgpu::Buffer>| {
            let mut r = vec![
                ub.as_entire_binding(),
                leaves.as_entire_binding(),
                bumps.as_entire_binding(),
                ops.as_entire_binding(),
                parent.as_entire_binding(),
                out.as_entire_binding(),
                hits.as_entire_binding(),
            ];
            if searching {
                r.push(search.as_entire_binding());
                r.push(counts.expect("a search counts").as_entire_binding());
            }
            compute::bind(gpu, pipeline, &r)
        };
        let groups = (w.div_ceil(8), h.div_ceil(8));
        let mut parent = compute::storage(
            gpu,
            "freeform root range",
            &[[view.near_ln, view.far_ln, 0.0, 2.0]],
        );
        let mut levels = Vec::new();
        let (mut parent_cols, mut is_top, mut tile_passes) = (1u32, 1u32, 0u32);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        for level in (1..=top_level).rev() {
            let size = 1u32 << level;
            let (cols, rows) = (w.div_ceil(size), h.div_ceil(size));
            let mut u = base;
            u.level = [size, cols, parent_cols, is_top];
            let ub = compute::uniform(gpu, "freeform level", &u);
            let out = compute::output(gpu, "freeform ranges", cols as u64 * rows as u64 * 16);
            // The longest walk a tile can have: the whole depth range at this level's cells.
            let cells =
                ((view.far_ln - view.near_ln) / (view.theta * size as f32)).ceil() as u32 + 2;
            let group = bind(&self.tile, &ub, &parent, &out, false, None);
            {
                let mut pass = enc.begin_compute_pass(&Default::default());
                pass.set_pipeline(&self.tile);
                pass.set_bind_group(0, &group, &[]);
                for _ in 0..cells.div_ceil(cells_per_pass) {
                    pass.dispatch_workgroups(cols.div_ceil(8), rows.div_ceil(8), 1);
                    tile_passes += 1;
                }
            }
            levels.push(out.clone());
            parent = out;
            parent_cols = cols;
            is_top = 0;
        }
        gpu.queue.submit([enc.finish()]);
        // Search rounds of at most `steps` steps per pixel, leaving room in lavapipe's loop
        // budget for the refinement of a sign change.
        let steps = (self.pass_loops / per_cell)
            .saturating_sub(REFINE_STEPS as u32 + 2)
            .max(1);
        let frame = |round: u32| {
            let mut u = base;
            u.depth[3] = steps as f32;
            u.level = [1, round, parent_cols, is_top];
            compute::uniform(gpu, "freeform pixel", &u)
        };
        let rounds = |pipeline: &wgpu::ComputePipeline, what: &str| -> Result<u32> {
            let counts = compute::output(gpu, "freeform unfinished", MAX_ROUNDS as u64 * 4);
            let mut round = 0;
            loop {
                let mut enc = gpu.device.create_command_encoder(&Default::default());
                for _ in 0..ROUNDS_PER_CHECK {
                    let ub = frame(round);
                    let group = bind(pipeline, &ub, &parent, &state, true, Some(&counts));
                    let mut pass = enc.begin_compute_pass(&Default::default());
                    pass.set_pipeline(pipeline);
                    pass.set_bind_group(0, &group, &[]);
                    pass.dispatch_workgroups(groups.0, groups.1, 1);
                    round += 1;
                }
                gpu.queue.submit([enc.finish()]);
                let bytes = read_buffer(gpu, &counts)?;
                let c: &[u32] = bytemuck::cast_slice(&bytes);
                if let Some(r) = c[..round as usize].iter().position(|&c| c == 0) {
                    return Ok(r as u32 + 1);
                }
                if round + ROUNDS_PER_CHECK > MAX_ROUNDS {
                    return Err(Error::limit(format!(
                        "the freeform {what} search had {} pixels unfinished after {round} rounds of {steps} steps",
                        c[round as usize - 1]
                    )));
                }
            }
        };
        let pixel_rounds = rounds(&self.pixel, "pixel")?;
        let ub = frame(0);
        let group = bind(&self.normals, &ub, &parent, &state, false, None);
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.normals);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(groups.0, groups.1, 1);
        }
        gpu.queue.submit([enc.finish()]);
        let shadow_rounds = match sun {
            Some(_) => rounds(&self.shadow, "shadow")?,
            None => 0,
        };
        gpu.wait();
        Ok(GpuCast {
            hits,
            state,
            leaves,
            levels,
            tile_passes,
            pixel_rounds,
            shadow_rounds,
        })
    }
}
