//! Terrain on the GPU: the height field and its min/max mipmap in storage buffers, per-sun
//! track uniforms, the hard-shadow mask kernel (`terrain_mask.wgsl`, tested against
//! `terrain::hard::relief::shadow_mask`) and the terrain frame (`terrain_render.wgsl`, tested against
//! `render::terrain_shading`).

use super::render_target::RenderTarget;
use super::terrain_air::{air_frame, TerrainAir};
use super::terrain_buffers::{grid_mesh, TerrainBuffers};
use super::terrain_pipelines::TerrainPipelines;
use super::themes::ThemeGpu;
use super::{compute, timing::PassTimer, Gpu};
use crate::error::{Error, Result};
use crate::heightmap::HeightMap;
use crate::render::terrain_shading::TerrainSettings;
use crate::terrain::horizon::map::HorizonMap;
use crate::terrain::sun::{Sun, Track, TrackKind};
use crate::terrain::MinMaxMipmap;
use glam::{Mat4, Vec3};

/// The `TerrainParams` uniform of `terrain_shadow.wgsl` (public for the layout test in
/// tests/gpu/layout.rs).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct TerrainParams {
    pub width: u32,
    pub height: u32,
    pub levels: u32,
    pub kind: u32,
    pub step_x: i32,
    pub step_y: i32,
    pub pad0: [u32; 2],
    pub ux: f32,
    pub uy: f32,
    pub inv_ux: f32,
    pub inv_uy: f32,
    pub rise_per_t: f32,
    pub max_height: f32,
    pub min_height: f32,
    pub metres_per_t: f32,
    pub alpha: f32,
    pub planet_radius: f32,
    pub sin_elevation0: f32,
    pub cos_elevation0: f32,
    pub sin_azimuth: f32,
    pub cos_azimuth: f32,
    pub cell_x: f32,
    pub cell_y: f32,
    pub tan_alpha: f32,
    pub horizon_w: f32,
    pub elevation_deg: f32,
    pub has_horizon: u32,
}

/// The `TerrainFrame` uniform of `terrain_render.wgsl` (public for the layout test in
/// tests/gpu/layout.rs).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct TerrainFrame {
    pub view_proj: [f32; 16],
    pub inv_view_proj: [f32; 16],
    pub eye: [f32; 4],
    pub sun: [f32; 4],
    pub cell: [f32; 4],
    pub sun_light: [f32; 4],
    pub fog_ext: [f32; 4],
    pub fog_rayleigh: [f32; 4],
    pub fog_mie: [f32; 4],
    pub fog_sun: [f32; 4],
    pub exposure: f32,
    pub flags: u32,
    pub min_height: f32,
    pub max_height_tint: f32,
    pub model: u32,
    pub pad: [u32; 3],
}

/// The horizon maps on the GPU: all planes stay on the CPU; the two around the sun's azimuth
/// are packed per texel into `TerrainBuffers::horizon_pair`, uploaded again only when the
/// sun's azimuth leaves their bracket (a sun moving in elevation, or within the bracket, costs
/// nothing).
struct HorizonGpu {
    map: HorizonMap,
    /// The planes in `horizon_pair`.
    pair: Option<(usize, usize)>,
}

/// GPU state for one height map.
pub struct TerrainRenderer {
    map_size: (u32, u32),
    buffers: TerrainBuffers,
    horizon: Option<HorizonGpu>,
    cell: [f32; 2],
    heights_range: (f32, f32),
    params_cpu: TerrainParams,
    mask_pipeline: wgpu::ComputePipeline,
    mask_groups: [wgpu::BindGroup; 2],
    mask_params: wgpu::Buffer,
    mask_out: wgpu::Buffer,
    pipelines: TerrainPipelines,
    render_groups: [wgpu::BindGroup; 2],
    frame: wgpu::Buffer,
    grid: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    grid_step: u32,
    pub target: RenderTarget,
    sun: Sun,
    /// The bake's theme set (a one-texel placeholder until [`TerrainRenderer::set_themes`]).
    themes: ThemeGpu,
    theme_group: wgpu::BindGroup,
    has_themes: bool,
    /// The air: Hillaire's tables and the sky pass.
    air: TerrainAir,
}

/// Most grid vertices along a side of the display mesh (the shading is per texel regardless).
pub const MAX_GRID: u32 = 512;

impl TerrainRenderer {
    /// Upload `map` and `mip` and create a `width`×`height` target. `grid_step` None picks the
    /// display-mesh decimation so that at most [`MAX_GRID`] vertices span a side.
    pub fn new(
        gpu: &Gpu,
        map: &HeightMap,
        mip: &MinMaxMipmap,
        width: u32,
        height: u32,
        grid_step: Option<u32>,
    ) -> Result<Self> {
        if (mip.map_width, mip.map_height) != (map.width, map.height) {
            return Err(Error::Internal("mipmap and height map sizes differ".into()));
        }
        let bytes = (map.heights.len() * 4) as u64;
        if bytes > gpu.info.max_storage_buffer_binding_size {
            return Err(Error::limit(format!(
                "a {}x{} height map needs {} MiB, over the adapter's {} MiB storage binding limit",
                map.width,
                map.height,
                bytes >> 20,
                gpu.info.max_storage_buffer_binding_size >> 20
            )));
        }
        let heights = compute::storage(gpu, "heights", &map.heights);
        let mip_data = compute::storage(gpu, "minmax mipmap", &mip.data);
        let levels: Vec<[u32; 4]> = mip
            .levels
            .iter()
            .map(|l| [l.width as u32, l.height as u32, l.offset as u32, 0])
            .collect();
        let mip_levels = compute::storage(gpu, "mip levels", &levels);
        let params_cpu = TerrainParams {
            width: map.width as u32,
            height: map.height as u32,
            levels: mip.levels.len() as u32,
            ..Default::default()
        };
        let params = compute::uniform(gpu, "terrain params", &params_cpu);
        let buffers = TerrainBuffers {
            params,
            heights,
            mip_data,
            mip_levels,
            // A placeholder until horizon maps are set (`has_horizon` = 0).
            horizon_pair: compute::storage(gpu, "horizon pair", &[0u32]),
        };
        let terrain_entries = |layout: &wgpu::BindGroupLayout| buffers.bind(gpu, layout);

        let mask_pipeline = compute::pipeline(gpu, "terrain_mask.wgsl", "main")?;
        let mask_params = compute::uniform(gpu, "mask params", &[0u32; 4]);
        let mask_out = compute::output(gpu, "mask", (map.width * map.height * 4) as u64);
        let mask_group0 = compute::bind(
            gpu,
            &mask_pipeline,
            &[
                mask_params.as_entire_binding(),
                mask_out.as_entire_binding(),
            ],
        );
        let mask_groups = [
            mask_group0,
            terrain_entries(&mask_pipeline.get_bind_group_layout(1)),
        ];

        let pipelines = TerrainPipelines::new(gpu)?;
        let frame = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("terrain frame"),
            size: std::mem::size_of::<TerrainFrame>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let g0 = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("terrain frame"),
            layout: &pipelines.layouts[0],
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: frame.as_entire_binding(),
            }],
        });
        let render_groups = [g0, terrain_entries(&pipelines.layouts[1])];
        let air = TerrainAir::new(gpu, &pipelines.module, &pipelines.layouts[3], &frame);
        let themes = ThemeGpu::upload(gpu, &crate::theme::ThemeSet::placeholder());
        let theme_group = themes.bind(gpu, &pipelines.layouts[2]);

        let step = grid_step
            .unwrap_or_else(|| (map.width.max(map.height) as u32).div_ceil(MAX_GRID))
            .max(1);
        let (grid, indices, index_count) =
            grid_mesh(gpu, map.width as u32, map.height as u32, step);
        let (lo, hi) = map.min_max();
        let mut r = TerrainRenderer {
            map_size: (map.width as u32, map.height as u32),
            buffers,
            horizon: None,
            cell: [map.cell_size[0] as f32, map.cell_size[1] as f32],
            heights_range: (lo, hi),
            params_cpu,
            mask_pipeline,
            mask_groups,
            mask_params,
            mask_out,
            pipelines,
            render_groups,
            frame,
            grid,
            indices,
            index_count,
            grid_step: step,
            target: RenderTarget::new(gpu, width, height),
            sun: Sun::new(135.0, 30.0)?,
            themes,
            theme_group,
            has_themes: false,
            air,
        };
        r.params_cpu.max_height = mip.max_height;
        r.params_cpu.min_height = mip.min_height;
        r.params_cpu.cell_x = r.cell[0];
        r.params_cpu.cell_y = r.cell[1];
        r.set_soft(gpu, crate::terrain::soft::model::SUN_RADIUS_DEG, None);
        r.set_sun(gpu, Sun::new(135.0, 30.0)?);
        Ok(r)
    }

    /// Set the sun: the track constants of `terrain::sun::Track`, rounded to f32.
    pub fn set_sun(&mut self, gpu: &Gpu, sun: Sun) {
        let t = Track::new(&sun, [self.cell[0] as f64, self.cell[1] as f64]);
        let p = &mut self.params_cpu;
        p.kind = match t.kind {
            TrackKind::Ray => 0,
            TrackKind::Zenith => 1,
            TrackKind::BelowHorizon => 2,
        };
        p.step_x = t.step_x as i32;
        p.step_y = t.step_y as i32;
        p.ux = t.ux as f32;
        p.uy = t.uy as f32;
        p.inv_ux = t.inv_ux as f32;
        p.inv_uy = t.inv_uy as f32;
        p.rise_per_t = t.rise_per_t as f32;
        p.metres_per_t = t.metres_per_t as f32;
        let (se, ce) = sun.elevation_deg.to_radians().sin_cos();
        (p.sin_elevation0, p.cos_elevation0) = (se as f32, ce as f32);
        let (sa, ca) = sun.azimuth_deg.to_radians().sin_cos();
        (p.sin_azimuth, p.cos_azimuth) = (sa as f32, ca as f32);
        p.elevation_deg = sun.elevation_deg as f32;
        self.sun = sun;
        self.upload_horizon(gpu);
        gpu.queue.write_buffer(
            &self.buffers.params,
            0,
            bytemuck::bytes_of(&self.params_cpu),
        );
    }

    /// Use `hm` (of this map) for hard shadows when [`TerrainSettings::horizon`] is set and for
    /// [`Self::shadow_mask_horizon`].
    pub fn set_horizon(&mut self, gpu: &Gpu, hm: HorizonMap) -> Result<()> {
        if (hm.width, hm.height) != (self.map_size.0 as usize, self.map_size.1 as usize) {
            return Err(Error::Internal(
                "horizon map and height map sizes differ".into(),
            ));
        }
        self.buffers.horizon_pair =
            compute::output(gpu, "horizon pair", (hm.width * hm.height * 4) as u64);
        self.horizon = Some(HorizonGpu {
            map: hm,
            pair: None,
        });
        self.mask_groups[1] = self
            .buffers
            .bind(gpu, &self.mask_pipeline.get_bind_group_layout(1));
        self.render_groups[1] = self.buffers.bind(gpu, &self.pipelines.layouts[1]);
        self.params_cpu.has_horizon = 1;
        self.set_sun(gpu, self.sun);
        Ok(())
    }

    /// Whether horizon maps are set.
    pub fn has_horizon(&self) -> bool {
        self.horizon.is_some()
    }

    /// Bracket the sun's azimuth in the horizon map and upload the pair of planes if it
    /// changed; sets the interpolation weight.
    fn upload_horizon(&mut self, gpu: &Gpu) {
        let Some(h) = self.horizon.as_mut() else {
            return;
        };
        let (k0, k1, w) = h.map.bracket(self.sun.azimuth_deg);
        self.params_cpu.horizon_w = w as f32;
        if h.pair != Some((k0, k1)) {
            let packed = h.map.packed_pair(k0, k1);
            gpu.queue
                .write_buffer(&self.buffers.horizon_pair, 0, bytemuck::cast_slice(&packed));
            h.pair = Some((k0, k1));
        }
    }

    /// Soft-shadow knobs: the sun's angular radius (degrees) and the planet radius (metres,
    /// None = flat ground).
    pub fn set_soft(&mut self, gpu: &Gpu, sun_radius_deg: f64, planet_radius_m: Option<f64>) {
        self.params_cpu.alpha = sun_radius_deg.to_radians() as f32;
        self.params_cpu.tan_alpha = sun_radius_deg.to_radians().tan() as f32;
        self.params_cpu.planet_radius = planet_radius_m.unwrap_or(0.0) as f32;
        gpu.queue.write_buffer(
            &self.buffers.params,
            0,
            bytemuck::bytes_of(&self.params_cpu),
        );
    }

    /// The hard-shadow mask of every texel from the horizon maps (the accelerated traversal's
    /// when none are set), computed on the GPU.
    pub fn shadow_mask_horizon(&self, gpu: &Gpu) -> Result<Vec<bool>> {
        Ok(self.run_mask(gpu, 3)?.iter().map(|&w| w != 0).collect())
    }

    /// The hard-shadow mask of every texel (row-major, true = shadow), computed on the GPU.
    pub fn shadow_mask(&self, gpu: &Gpu, accelerated: bool) -> Result<Vec<bool>> {
        Ok(self
            .run_mask(gpu, accelerated as u32)?
            .iter()
            .map(|&w| w != 0)
            .collect())
    }

    /// The soft lit fraction of every texel (row-major), by branch-and-bound on the GPU.
    pub fn lit_fraction(&self, gpu: &Gpu) -> Result<Vec<f32>> {
        Ok(self
            .run_mask(gpu, 2)?
            .iter()
            .map(|&w| f32::from_bits(w))
            .collect())
    }

    fn run_mask(&self, gpu: &Gpu, method: u32) -> Result<Vec<u32>> {
        gpu.queue.write_buffer(
            &self.mask_params,
            0,
            bytemuck::cast_slice(&[method, 0, 0, 0]),
        );
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.mask_pipeline);
            pass.set_bind_group(0, &self.mask_groups[0], &[]);
            pass.set_bind_group(1, &self.mask_groups[1], &[]);
            pass.dispatch_workgroups(self.map_size.0.div_ceil(8), self.map_size.1.div_ceil(8), 1);
        }
        gpu.queue.submit([enc.finish()]);
        let words = super::readback::read_buffer(gpu, &self.mask_out)?;
        let words: &[u32] = bytemuck::cast_slice(&words);
        Ok(words[..(self.map_size.0 * self.map_size.1) as usize].to_vec())
    }

    /// A camera over the map from the south, looking at its centre (world: x east, y up,
    /// z south; vertical exaggeration from `s`).
    pub fn default_view(&self, s: &TerrainSettings) -> (Vec3, Vec3) {
        let w = self.map_size.0 as f32 * self.cell[0];
        let d = self.map_size.1 as f32 * self.cell[1];
        let centre = Vec3::new(
            0.5 * w,
            self.heights_range.0 * s.vertical_exaggeration,
            0.5 * d,
        );
        let size = w.max(d);
        (
            centre + Vec3::new(0.1 * size, 0.38 * size, 0.72 * size),
            centre,
        )
    }

    /// Record the terrain frame for `view_proj` seen from `eye` (and the sky by the same
    /// atmosphere model). Hillaire's tables are rebuilt first when the sun or the eye's
    /// altitude moved.
    pub fn record(
        &mut self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        view_proj: Mat4,
        eye: Vec3,
        s: &TerrainSettings,
        timer: &mut PassTimer,
    ) -> Result<()> {
        use crate::atmosphere::Model;
        let dir = self.sun.direction();
        let k =
            crate::terrain::hard::relief::k_shadow(&self.sun, s.k_dark as f64, s.k_bright as f64)
                as f32;
        // True altitudes (the display exaggerates heights).
        let exaggeration = s.vertical_exaggeration.max(1e-6) as f64;
        let eye_altitude = (eye.y as f64 / exaggeration).max(1.0);
        let ground = 0.5 * (self.heights_range.0 + self.heights_range.1) as f64;
        let air = air_frame(
            &self.air.atmosphere,
            s.atmosphere,
            self.sun.toward_y_up_f64(),
            eye_altitude,
            ground.max(0.0),
            s.sun_strength,
        );
        if s.atmosphere == Model::Hillaire {
            let extent = (self.map_size.0 as f64 * self.cell[0] as f64)
                .hypot(self.map_size.1 as f64 * self.cell[1] as f64);
            let range = (2.0 * extent).max(50_000.0);
            self.air.prepare_tables(
                gpu,
                &self.pipelines.layouts[3],
                &self.sun,
                eye_altitude,
                range,
            )?;
        }
        let f = TerrainFrame {
            view_proj: view_proj.to_cols_array(),
            inv_view_proj: view_proj.inverse().to_cols_array(),
            eye: eye.extend(1.0).to_array(),
            sun: [dir[0] as f32, dir[1] as f32, dir[2] as f32, k],
            cell: [
                self.cell[0],
                self.cell[1],
                s.vertical_exaggeration,
                self.grid_step as f32,
            ],
            sun_light: air.sun_light,
            fog_ext: air.fog_ext,
            fog_rayleigh: air.fog_rayleigh,
            fog_mie: air.fog_mie,
            fog_sun: air.fog_sun,
            exposure: s.exposure,
            flags: s.shadows as u32
                | ((s.atmosphere != Model::None) as u32) << 1
                | (s.soft as u32) << 2
                | ((s.horizon && self.horizon.is_some()) as u32) << 3
                | ((s.themes && self.has_themes) as u32) << 4,
            min_height: self.heights_range.0,
            max_height_tint: self.heights_range.1,
            model: air.model,
            pad: [0; 3],
        };
        gpu.queue
            .write_buffer(&self.frame, 0, bytemuck::bytes_of(&f));
        let mut pass = self.target.begin_pass(enc, "terrain", s.background, timer);
        let themed = s.themes && self.has_themes;
        pass.set_pipeline(
            self.pipelines
                .get(gpu, themed, s.atmosphere == Model::Hillaire),
        );
        pass.set_bind_group(0, &self.render_groups[0], &[]);
        pass.set_bind_group(1, &self.render_groups[1], &[]);
        pass.set_bind_group(2, &self.theme_group, &[]);
        pass.set_bind_group(3, &self.air.terrain_group, &[]);
        pass.set_vertex_buffer(0, self.grid.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..self.index_count, 0, 0..1);
        if s.atmosphere != Model::None {
            self.air.record_sky(&mut pass);
        }
        Ok(())
    }

    /// Texture the terrain with `set` (its index map spans the whole height map) instead of
    /// the hypsometric tint.
    pub fn set_themes(&mut self, gpu: &Gpu, set: &crate::theme::ThemeSet) {
        self.themes = ThemeGpu::upload(gpu, set);
        self.theme_group = self.themes.bind(gpu, &self.pipelines.layouts[2]);
        self.has_themes = true;
    }

    pub fn has_themes(&self) -> bool {
        self.has_themes
    }

    /// Move the theme borders to animation shift `shift` ([`crate::theme::ThemeSet::shift`]).
    pub fn set_theme_shift(&mut self, gpu: &Gpu, shift: [f32; 2]) {
        self.themes.set_shift(gpu, shift);
    }

    pub fn resize(&mut self, gpu: &Gpu, width: u32, height: u32) {
        self.target = RenderTarget::new(gpu, width, height);
    }

    /// The top-down orthographic view in which pixel (x, y) of a map-sized image sees the
    /// centre of texel (x, y) (north up): the map view of the twin test.
    pub fn map_view(&self) -> (Mat4, Vec3) {
        let (w, h) = (
            self.map_size.0 as f32 * self.cell[0],
            self.map_size.1 as f32 * self.cell[1],
        );
        let top = self.heights_range.1.abs().max(self.heights_range.0.abs()) * 4.0 + 1.0;
        let eye = Vec3::new(0.0, top, 0.0);
        // Looking down −y with north (−z) up in the image.
        let view = crate::render::camera::look_at(eye, eye - Vec3::Y, Vec3::NEG_Z);
        let proj = crate::render::camera::orthographic(0.0, w, -h, 0.0, 0.0, 2.0 * top + 1.0);
        (proj * view, eye)
    }
}
