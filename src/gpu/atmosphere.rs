//! Hillaire's tables on the GPU (`shaders/atmosphere.wgsl`): the four build kernels, storage
//! buffers of `vec4<f32>` texels (the layouts of `atmosphere::twin`), and a test kernel
//! (`shaders/atmosphere_kernel.wgsl`) that evaluates the lookups a renderer calls.
//! CPU twin: `atmosphere::lut::Luts::build`.
//!
//! A render shader includes `atmosphere_lookup.wgsl` (`//! include atmosphere_lookup.wgsl`),
//! which declares, in group 3: binding 0 the uniform [`AtmosphereTables::params`], binding 1
//! the read-only storage `sky_view`, binding 2 the read-only storage `aerial`; it calls
//! `sky_radiance(dir)` and `aerial_perspective(dir, distance_km)`. The pipeline's group 3
//! layout comes from [`AtmosphereTables::layout_entries`] (or the shader, with an automatic
//! layout) and its bind group from [`AtmosphereTables::bind_group`]. When the sun or the
//! eye's altitude changes, [`AtmosphereTables::update`] rebuilds the two view-dependent
//! tables (sky view, aerial volume) in place, so bind groups stay valid.

use super::compute::{self, output, storage, uniform};
use super::{readback, Gpu};
use crate::atmosphere::lut::Luts;
use crate::atmosphere::twin::{
    AtmosphereGpu, AERIAL_SIZE, MULTI_SCATTERING_SIZE, SKY_VIEW_SIZE, TRANSMITTANCE_SIZE,
};
use crate::error::Result;

const SHADER: &str = "atmosphere.wgsl";
const KERNEL: &str = "atmosphere_kernel.wgsl";
/// The group `atmosphere_lookup.wgsl` declares its bindings in.
pub const LOOKUP_GROUP: u32 = 3;

/// The tables of one eye altitude and sun, on the GPU.
pub struct AtmosphereTables {
    pub params: wgpu::Buffer,
    pub transmittance: wgpu::Buffer,
    pub multi_scattering: wgpu::Buffer,
    pub sky_view: wgpu::Buffer,
    pub aerial: wgpu::Buffer,
    /// The parameters the tables were built for.
    current: AtmosphereGpu,
    /// Sky-view and aerial kernels with their bind groups, kept for [`Self::update`].
    view_kernels: [(wgpu::ComputePipeline, wgpu::BindGroup, usize); 2],
}

fn texels(n: usize) -> u64 {
    16 * n as u64
}

/// Bind `(binding, buffer)` pairs to group 0 of `pipeline`.
fn bind(
    gpu: &Gpu,
    pipeline: &wgpu::ComputePipeline,
    entries: &[(u32, &wgpu::Buffer)],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = entries
        .iter()
        .map(|(b, buf)| wgpu::BindGroupEntry {
            binding: *b,
            resource: buf.as_entire_binding(),
        })
        .collect();
    gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("atmosphere"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    })
}

fn run(gpu: &Gpu, entry: &str, entries: &[(u32, &wgpu::Buffer)], invocations: usize) -> Result<()> {
    let pipeline = compute::pipeline(gpu, SHADER, entry)?;
    let group = bind(gpu, &pipeline, entries);
    compute::dispatch(
        gpu,
        &pipeline,
        &group,
        [invocations.div_ceil(64) as u32, 1, 1],
    );
    Ok(())
}

/// The parameters with the view-dependent ones (eye altitude, aerial range, sun) zeroed: two
/// sets equal here share their transmittance and multiple-scattering tables.
fn medium_only(p: &AtmosphereGpu) -> AtmosphereGpu {
    let mut m = *p;
    m.radii[2] = 0.0;
    m.radii[3] = 0.0;
    m.sun = [0.0; 4];
    m
}

impl AtmosphereTables {
    /// Build the four tables for `params` (transmittance, then multiple scattering, then the
    /// sky view and the aerial-perspective volume).
    pub fn build(gpu: &Gpu, params: &AtmosphereGpu) -> Result<AtmosphereTables> {
        let [tw, th] = TRANSMITTANCE_SIZE;
        let [mw, mh] = MULTI_SCATTERING_SIZE;
        let [sw, sh] = SKY_VIEW_SIZE;
        let [ax, ay, az] = AERIAL_SIZE;
        let p = uniform(gpu, "atmosphere params", params);
        let transmittance = output(gpu, "transmittance", texels(tw * th));
        let multi_scattering = output(gpu, "multi scattering", texels(mw * mh));
        let sky_view = output(gpu, "sky view", texels(sw * sh));
        let aerial = output(gpu, "aerial perspective", texels(2 * ax * ay * az));
        let read = [(0, &p), (1, &transmittance), (2, &multi_scattering)];
        let kernel = |entry: &str, target: &wgpu::Buffer, n: usize| {
            let pipeline = compute::pipeline(gpu, SHADER, entry)?;
            let group = bind(gpu, &pipeline, &[read[0], read[1], read[2], (5, target)]);
            Ok::<_, crate::error::Error>((pipeline, group, n))
        };
        let view_kernels = [
            kernel("build_sky_view", &sky_view, sw * sh)?,
            kernel("build_aerial", &aerial, ax * ay * az)?,
        ];
        let t = AtmosphereTables {
            params: p,
            transmittance,
            multi_scattering,
            sky_view,
            aerial,
            current: *params,
            view_kernels,
        };
        t.build_medium(gpu)?;
        t.build_view_on(gpu);
        Ok(t)
    }

    /// Transmittance, then multiple scattering (they depend on the medium only).
    fn build_medium(&self, gpu: &Gpu) -> Result<()> {
        let [tw, th] = TRANSMITTANCE_SIZE;
        let [mw, mh] = MULTI_SCATTERING_SIZE;
        run(
            gpu,
            "build_transmittance",
            &[(0, &self.params), (5, &self.transmittance)],
            tw * th,
        )?;
        run(
            gpu,
            "build_multi_scattering",
            &[
                (0, &self.params),
                (1, &self.transmittance),
                (5, &self.multi_scattering),
            ],
            mw * mh,
        )
    }

    /// The sky view and the aerial volume, with the kept pipelines.
    fn build_view_on(&self, gpu: &Gpu) {
        for (pipeline, group, n) in &self.view_kernels {
            compute::dispatch(gpu, pipeline, group, [n.div_ceil(64) as u32, 1, 1]);
        }
    }

    /// New parameters for the same buffers (bind groups made from them stay valid). When only
    /// the eye's altitude, the aerial range or the sun differ from the last build, this
    /// rebuilds just the sky view and the aerial volume (two dispatches, no pipeline
    /// creation); otherwise all four tables.
    pub fn update(&mut self, gpu: &Gpu, params: &AtmosphereGpu) -> Result<()> {
        if *params == self.current {
            return Ok(());
        }
        gpu.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(params));
        if medium_only(params) != medium_only(&self.current) {
            self.build_medium(gpu)?;
        }
        self.current = *params;
        self.build_view_on(gpu);
        Ok(())
    }

    /// The parameters the tables hold.
    pub fn params_value(&self) -> &AtmosphereGpu {
        &self.current
    }

    /// The group-3 layout entries of `atmosphere_lookup.wgsl`, visible to `visibility`.
    pub fn layout_entries(visibility: wgpu::ShaderStages) -> [wgpu::BindGroupLayoutEntry; 3] {
        let entry = |binding, ty| compute::buffer_entry(binding, visibility, ty);
        let ro = wgpu::BufferBindingType::Storage { read_only: true };
        [
            entry(0, wgpu::BufferBindingType::Uniform),
            entry(1, ro),
            entry(2, ro),
        ]
    }

    /// A bind group for `layout` (group 3 of a pipeline whose shader includes
    /// `atmosphere_lookup.wgsl`): the parameters, the sky view and the aerial volume.
    pub fn bind_group(&self, gpu: &Gpu, layout: &wgpu::BindGroupLayout) -> wgpu::BindGroup {
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("atmosphere lookups"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: self.sky_view.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: self.aerial.as_entire_binding(),
                },
            ],
        })
    }

    /// Read the tables back (to compare with `Luts::build`).
    pub fn read(&self, gpu: &Gpu, params: &AtmosphereGpu) -> Result<Luts> {
        let quads = |b: &wgpu::Buffer| -> Result<Vec<[f32; 4]>> {
            let f = readback::read_f32(gpu, b)?;
            Ok(f.chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect())
        };
        Ok(Luts {
            params: *params,
            transmittance: quads(&self.transmittance)?,
            multi_scattering: quads(&self.multi_scattering)?,
            sky_view: quads(&self.sky_view)?,
            aerial: quads(&self.aerial)?,
        })
    }

    /// Run the `evaluate` kernel: per query `[dir.x, dir.y, dir.z, distance_km]`, four texels
    /// (sky radiance, aerial in-scattering, aerial transmittance, fog of `L0 = 0.25` with the
    /// eye's air).
    pub fn evaluate(&self, gpu: &Gpu, queries: &[[f32; 4]]) -> Result<Vec<[f32; 4]>> {
        let q = storage(gpu, "atmosphere queries", queries);
        let out = output(gpu, "atmosphere evaluations", texels(4 * queries.len()));
        let pipeline = compute::pipeline(gpu, KERNEL, "evaluate")?;
        let g0 = bind(gpu, &pipeline, &[(0, &out), (1, &q)]);
        let empty = |i| {
            gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &pipeline.get_bind_group_layout(i),
                entries: &[],
            })
        };
        let (g1, g2) = (empty(1), empty(2));
        let g3 = self.bind_group(gpu, &pipeline.get_bind_group_layout(LOOKUP_GROUP));
        compute::dispatch_groups(
            gpu,
            &pipeline,
            &[(0, &g0), (1, &g1), (2, &g2), (LOOKUP_GROUP, &g3)],
            [queries.len().div_ceil(64) as u32, 1, 1],
        );
        let f = readback::read_f32(gpu, &out)?;
        Ok(f.chunks_exact(4)
            .take(4 * queries.len())
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect())
    }
}
