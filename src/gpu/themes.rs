//! Thematic textures on the GPU: a [`ThemeSet`] packed into one u32 buffer (index levels
//! Colour Cell Compressed, exception blocks, theme texels, turbulence map, sRGB table, classes,
//! level table) and the `ThemeParams` uniform of `shaders/theme.wgsl`, bound as group 2 by the
//! terrain frame; and the test kernel (`theme_kernel.wgsl`) that evaluates the albedo at given
//! points, compared with `theme::compose` in tests/gpu/themes.rs.

use super::{compute, readback, Gpu};
use crate::error::Result;
use crate::theme::textures::srgb_table;
use crate::theme::{Border, ThemeSet};

/// The `ThemeParams` uniform of `theme.wgsl` (public for the layout test).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ThemeParams {
    pub words_at: u32,
    pub exceptions_at: u32,
    pub textures_at: u32,
    pub noise_at: u32,
    pub lut_at: u32,
    pub classes_at: u32,
    pub levels_at: u32,
    pub index_levels: u32,
    pub tex_size: u32,
    pub tex_levels: u32,
    pub per_theme: u32,
    pub noise_size: u32,
    pub shift: [f32; 2],
    pub index_size: [f32; 2],
}

/// The set packed for `theme.wgsl`: the buffer's words and the uniform (frame 0; set
/// `shift` per frame with [`ThemeSet::shift`]).
pub fn pack(set: &ThemeSet) -> (Vec<u32>, ThemeParams) {
    let levels = set.compressed_levels();
    let mut data: Vec<u32> = Vec::new();
    let mut p = ThemeParams {
        index_levels: levels.len() as u32,
        tex_size: set.textures.size as u32,
        tex_levels: set.textures.levels as u32,
        per_theme: set.textures.per_theme() as u32,
        noise_size: set.noise.size as u32,
        index_size: [
            set.index.levels[0].width as f32,
            set.index.levels[0].height as f32,
        ],
        ..Default::default()
    };
    let mut table = Vec::with_capacity(levels.len() * 4);
    p.words_at = data.len() as u32;
    for c in &levels {
        table.extend([0, c.width as u32, c.height as u32, 0]);
        let at = table.len() - 4;
        table[at] = data.len() as u32 - p.words_at;
        data.extend(&c.words);
    }
    p.exceptions_at = data.len() as u32;
    let mut exceptions = 0u32;
    for (i, c) in levels.iter().enumerate() {
        table[i * 4 + 3] = exceptions;
        for block in &c.exceptions {
            data.extend(
                block
                    .chunks(4)
                    .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            );
        }
        exceptions += c.exceptions.len() as u32;
    }
    p.textures_at = data.len() as u32;
    data.extend(set.textures.texels.iter().map(|t| u32::from_le_bytes(*t)));
    p.noise_at = data.len() as u32;
    data.extend(set.noise.values.iter().flat_map(|v| v.map(f32::to_bits)));
    p.lut_at = data.len() as u32;
    data.extend(srgb_table().iter().map(|v| v.to_bits()));
    p.classes_at = data.len() as u32;
    for c in &set.classes {
        let (amplitude, scale, width) = match c.border {
            Border::Fractal { amplitude, scale } => (amplitude, scale, 0.0),
            Border::Natural => (0.0, 1.0, 0.0),
            Border::Blend { width } => (0.0, 1.0, width),
        };
        let t = c.tiling;
        data.extend([c.theme, c.border.kind_code()]);
        data.extend([amplitude, scale, width, t.tile, t.warp, t.warp_scale].map(f32::to_bits));
    }
    p.levels_at = data.len() as u32;
    data.extend(table);
    (data, p)
}

/// A theme set on the GPU.
pub struct ThemeGpu {
    pub params: ThemeParams,
    pub uniform: wgpu::Buffer,
    pub data: wgpu::Buffer,
}

impl ThemeGpu {
    pub fn upload(gpu: &Gpu, set: &ThemeSet) -> ThemeGpu {
        let (data, params) = pack(set);
        ThemeGpu {
            params,
            uniform: compute::uniform(gpu, "theme params", &params),
            data: compute::storage(gpu, "theme data", &data),
        }
    }

    /// Set the animation shift (noise periods).
    pub fn set_shift(&mut self, gpu: &Gpu, shift: [f32; 2]) {
        self.params.shift = shift;
        gpu.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&self.params));
    }

    /// The bind group of group 2 for `layout`.
    pub fn bind(&self, gpu: &Gpu, layout: &wgpu::BindGroupLayout) -> wgpu::BindGroup {
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("themes"),
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: self.data.as_entire_binding(),
                },
            ],
        })
    }
}

/// The albedo (and the class shown unperturbed, as f32) at points (x, y, footprint) on the
/// GPU, animation frame `frame`: the test kernel.
pub fn albedo_at(
    gpu: &Gpu,
    set: &ThemeSet,
    frame: u32,
    points: &[[f32; 3]],
) -> Result<Vec<[f32; 4]>> {
    let mut themes = ThemeGpu::upload(gpu, set);
    themes.set_shift(gpu, set.shift(frame));
    let pipeline = compute::pipeline(gpu, "theme_kernel.wgsl", "theme_albedo_kernel")?;
    let pts: Vec<[f32; 4]> = points.iter().map(|p| [p[0], p[1], p[2], 0.0]).collect();
    let input = compute::storage(gpu, "points", &pts);
    let out = compute::output(gpu, "albedo", (pts.len() * 16) as u64);
    let g0 = compute::bind(
        gpu,
        &pipeline,
        &[input.as_entire_binding(), out.as_entire_binding()],
    );
    let g1 = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(1),
        entries: &[],
    });
    let g2 = themes.bind(gpu, &pipeline.get_bind_group_layout(2));
    let groups = (pts.len() as u32).div_ceil(64);
    compute::dispatch_groups(
        gpu,
        &pipeline,
        &[(0, &g0), (1, &g1), (2, &g2)],
        [groups, 1, 1],
    );
    let v = readback::read_f32(gpu, &out)?;
    Ok(v.chunks(4)
        .take(pts.len())
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect())
}
