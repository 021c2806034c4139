//! Hillaire's tables on the GPU (`shaders/atmosphere.wgsl`): the four build kernels, storage
//! buffers of `vec4<f32>` texels (the layouts of `atmosphere::twin`), and a test kernel that
//! evaluates the lookups a renderer calls. CPU twin: `atmosphere::lut::Luts::build`.
//!
//! A render pass binds, in its own group, the uniform [`AtmosphereTables::params`] and the
//! read-only storage buffers `transmittance`, `multi_scattering`, `sky_view`, `aerial`
//! (bindings 0 to 4 of `atmosphere.wgsl`), and calls `sky_radiance(dir)` and
//! `aerial_perspective(dir, distance_km)`.

use super::compute::{self, output, storage, uniform};
use super::{readback, Gpu};
use crate::atmosphere::lut::Luts;
use crate::atmosphere::twin::{
    AtmosphereGpu, AERIAL_SIZE, MULTI_SCATTERING_SIZE, SKY_VIEW_SIZE, TRANSMITTANCE_SIZE,
};
use crate::error::Result;

const SHADER: &str = "atmosphere.wgsl";

/// The tables of one eye altitude and sun, on the GPU.
pub struct AtmosphereTables {
    pub params: wgpu::Buffer,
    pub transmittance: wgpu::Buffer,
    pub multi_scattering: wgpu::Buffer,
    pub sky_view: wgpu::Buffer,
    pub aerial: wgpu::Buffer,
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

impl AtmosphereTables {
    /// Build the four tables for `params` (transmittance, then multiple scattering, then the
    /// sky view and the aerial-perspective volume).
    pub fn build(gpu: &Gpu, params: &AtmosphereGpu) -> Result<AtmosphereTables> {
        let [tw, th] = TRANSMITTANCE_SIZE;
        let [mw, mh] = MULTI_SCATTERING_SIZE;
        let [sw, sh] = SKY_VIEW_SIZE;
        let [ax, ay, az] = AERIAL_SIZE;
        let t = AtmosphereTables {
            params: uniform(gpu, "atmosphere params", params),
            transmittance: output(gpu, "transmittance", texels(tw * th)),
            multi_scattering: output(gpu, "multi scattering", texels(mw * mh)),
            sky_view: output(gpu, "sky view", texels(sw * sh)),
            aerial: output(gpu, "aerial perspective", texels(2 * ax * ay * az)),
        };
        run(
            gpu,
            "build_transmittance",
            &[(0, &t.params), (5, &t.transmittance)],
            tw * th,
        )?;
        run(
            gpu,
            "build_multi_scattering",
            &[
                (0, &t.params),
                (1, &t.transmittance),
                (5, &t.multi_scattering),
            ],
            mw * mh,
        )?;
        let read = [
            (0, &t.params),
            (1, &t.transmittance),
            (2, &t.multi_scattering),
        ];
        run(
            gpu,
            "build_sky_view",
            &[read[0], read[1], read[2], (5, &t.sky_view)],
            sw * sh,
        )?;
        run(
            gpu,
            "build_aerial",
            &[read[0], read[1], read[2], (5, &t.aerial)],
            ax * ay * az,
        )?;
        Ok(t)
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
        run(
            gpu,
            "evaluate",
            &[
                (0, &self.params),
                (3, &self.sky_view),
                (4, &self.aerial),
                (5, &out),
                (6, &q),
            ],
            queries.len(),
        )?;
        let f = readback::read_f32(gpu, &out)?;
        Ok(f.chunks_exact(4)
            .take(4 * queries.len())
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect())
    }
}
