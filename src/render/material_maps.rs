//! Material textures as the player samples them: mip chains and filtered lookups, the CPU twin
//! of the texture reads in `shaders/mesh_shade.wgsl` and `shaders/shadow_masked.wgsl`.
//!
//! The GPU uploads exactly the levels built here ([`SceneMaps::new`]), so a GPU lookup and
//! [`MipChain::sample`] read the same bytes and differ only by the sampler's filtering precision.
//!
//! - **Albedo chains** (one per texture a material names as its albedo): RGBA8 with RGB
//!   sRGB-encoded and alpha linear (what `Rgba8UnormSrgb` decodes), each level the 2×2 box mean
//!   of the one above *in linear space*, re-encoded (averaging sRGB bytes would darken edges).
//! - **Mask chains** (one per alpha-masked material): one byte per texel, `factor × channel`
//!   (the rule [`crate::scene::texture::AlphaMask`] states). Box-filtered alpha shrinks foliage
//!   in the distance (a leaf's thin parts average below the cutoff), so each level is rescaled
//!   until the fraction of texels at or above the cutoff equals level 0's (Castaño 2010,
//!   "Computing alpha mipmaps").
//!
//! Lookups follow the Vulkan sampler rules: texel centres at half-integers, bilinear within a
//! level, linear between levels, wrap modes applied to integer texel indices. The level of
//! detail is the isotropic one, `log2` of the larger screen-axis footprint in texels; the GPU
//! sampler adds anisotropic filtering on top, so the two agree exactly where the footprint is
//! round (a surface facing the camera) and the GPU is sharper at grazing angles.
//!
//! Level sizes are `max(1, size >> level)` (an odd side drops its last texel, the usual 2×2
//! reduction; a side of 1 stays 1). Textures larger than the device's limit start at the first level that fits.

use crate::scene::texture::{channel_value, srgb_table, wrap_index, TextureRef, Wrap};
use crate::scene::texture::{linear_to_srgb, AlphaMask, Channel, Texture};
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// One mip level: `width · height · channels` bytes, row-major from the top row.
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<u8>,
}

/// What a chain's bytes mean.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// RGBA8, RGB sRGB-encoded, alpha linear.
    SrgbAlpha,
    /// One linear byte per texel.
    Linear8,
}

/// A texture and its smaller levels.
#[derive(Clone, Debug, PartialEq)]
pub struct MipChain {
    pub encoding: Encoding,
    pub levels: Vec<Level>,
}

/// How a material reads one chain.
#[derive(Clone, Debug, PartialEq)]
pub struct Lookup {
    /// Affine map from vertex texture coordinates to image coordinates ([`TextureRef`]).
    pub transform: [[f32; 3]; 2],
    pub wrap: [Wrap; 2],
}

impl Lookup {
    fn of(r: &TextureRef) -> Self {
        Lookup {
            transform: r.transform,
            wrap: r.wrap,
        }
    }

    /// Image coordinates of vertex texture coordinates `uv`.
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let [a, b] = self.transform;
        Vec2::new(
            a[0] * uv.x + a[1] * uv.y + a[2],
            b[0] * uv.x + b[1] * uv.y + b[2],
        )
    }
}

/// A material's maps.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialMaps {
    /// Albedo factor (linear RGB) the texture is multiplied by.
    pub factor: Vec3,
    /// Index into [`SceneMaps::albedo`] and how it is read.
    pub albedo: Option<(usize, Lookup)>,
    /// Index into [`SceneMaps::masks`], how it is read and the cutoff below which the surface
    /// is cut away.
    pub mask: Option<(usize, Lookup, f32)>,
    /// The material is cut away everywhere (an alpha factor below the cutoff, no texture).
    pub hidden: bool,
}

/// Every material's maps and the chains they read.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneMaps {
    pub albedo: Vec<MipChain>,
    pub masks: Vec<MipChain>,
    pub materials: Vec<MaterialMaps>,
}

impl SceneMaps {
    /// The chains of `scene`'s materials, each starting at its first level no side of which
    /// exceeds `max_size` (a device's `max_texture_dimension_2d`).
    pub fn new(scene: &Scene, max_size: u32) -> Self {
        let mut albedo_of_texture: Vec<Option<usize>> = vec![None; scene.textures.len()];
        let mut albedo_sources = Vec::new();
        let mut mask_sources = Vec::new();
        let mut materials = Vec::with_capacity(scene.materials.len());
        for m in &scene.materials {
            let albedo = m.albedo_texture.as_ref().map(|r| {
                let slot = *albedo_of_texture[r.texture as usize].get_or_insert_with(|| {
                    albedo_sources.push(r.texture as usize);
                    albedo_sources.len() - 1
                });
                (slot, Lookup::of(r))
            });
            let (mask, hidden) = match &m.alpha {
                None => (None, false),
                Some(a) => match &a.texture {
                    None => (None, a.cuts(a.factor)),
                    Some((r, channel)) => {
                        mask_sources.push((r.texture as usize, a.clone(), *channel));
                        (
                            Some((mask_sources.len() - 1, Lookup::of(r), a.cutoff)),
                            false,
                        )
                    }
                },
            };
            materials.push(MaterialMaps {
                factor: Vec3::from(m.albedo),
                albedo,
                mask,
                hidden,
            });
        }
        let albedo = albedo_sources
            .par_iter()
            .map(|&t| skip_to_fit(albedo_chain(&scene.textures[t]), max_size))
            .collect();
        let masks = mask_sources
            .par_iter()
            .map(|(t, a, c)| skip_to_fit(mask_chain(&scene.textures[*t], a, *c), max_size))
            .collect();
        SceneMaps {
            albedo,
            masks,
            materials,
        }
    }

    /// Linear albedo of material `m` at vertex texture coordinates `uv` and level of detail
    /// `lod` (of the albedo texture's level 0); `None` when the material has no albedo texture.
    pub fn albedo_at(&self, m: usize, uv: Vec2, lod: f32) -> Option<Vec3> {
        let mm = &self.materials[m];
        let (i, look) = mm.albedo.as_ref()?;
        let s = self.albedo[*i].sample(look.apply(uv), look.wrap, lod);
        Some(mm.factor * Vec3::new(s[0], s[1], s[2]))
    }

    /// Whether material `m` is there (not cut away) at `uv` and `lod` (of its mask's level 0).
    pub fn opaque_at(&self, m: usize, uv: Vec2, lod: f32) -> bool {
        let mm = &self.materials[m];
        if mm.hidden {
            return false;
        }
        match &mm.mask {
            None => true,
            Some((i, look, cutoff)) => {
                self.masks[*i].sample(look.apply(uv), look.wrap, lod)[0] >= *cutoff
            }
        }
    }

    /// Level-0 size of the chain material `m`'s albedo (or else mask) reads, for levels of
    /// detail; `None` for an untextured material.
    pub fn base_size(&self, m: usize) -> Option<(u32, u32)> {
        let mm = &self.materials[m];
        let chain = match (&mm.albedo, &mm.mask) {
            (Some((i, _)), _) => &self.albedo[*i],
            (None, Some((i, _, _))) => &self.masks[*i],
            (None, None) => return None,
        };
        Some((chain.levels[0].width, chain.levels[0].height))
    }
}

/// The level of detail of a lookup whose image coordinates change by `dx` and `dy` per pixel
/// step along the screen axes, in a `width`×`height` level 0: `log2` of the larger footprint in
/// texels (the Vulkan isotropic rule).
pub fn level_of_detail(dx: Vec2, dy: Vec2, width: u32, height: u32) -> f32 {
    let s = Vec2::new(width as f32, height as f32);
    let rho = (dx * s).length().max((dy * s).length());
    if rho > 0.0 {
        rho.log2()
    } else {
        f32::NEG_INFINITY
    }
}

impl MipChain {
    /// Bytes per texel.
    pub fn channels(&self) -> usize {
        match self.encoding {
            Encoding::SrgbAlpha => 4,
            Encoding::Linear8 => 1,
        }
    }

    /// Filtered value at image coordinates `uv` and level of detail `lod`: linear RGBA for
    /// [`Encoding::SrgbAlpha`], the value in `[0]` for [`Encoding::Linear8`].
    pub fn sample(&self, uv: Vec2, wrap: [Wrap; 2], lod: f32) -> [f32; 4] {
        let last = (self.levels.len() - 1) as f32;
        let lod = if lod.is_nan() {
            0.0
        } else {
            lod.clamp(0.0, last)
        };
        let l0 = lod.floor();
        let t = lod - l0;
        let a = self.bilinear(l0 as usize, uv, wrap);
        if t == 0.0 {
            return a;
        }
        let b = self.bilinear(l0 as usize + 1, uv, wrap);
        std::array::from_fn(|c| a[c] + (b[c] - a[c]) * t)
    }

    /// Bilinear value of level `l` at image coordinates `uv`.
    pub fn bilinear(&self, l: usize, uv: Vec2, wrap: [Wrap; 2]) -> [f32; 4] {
        let level = &self.levels[l];
        let x = uv.x as f64 * level.width as f64 - 0.5;
        let y = uv.y as f64 * level.height as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let xs = [x0, x0 + 1].map(|i| wrap_index(i, level.width, wrap[0]) as usize);
        let ys = [y0, y0 + 1].map(|i| wrap_index(i, level.height, wrap[1]) as usize);
        let mut out = [0.0f32; 4];
        for (j, &yy) in ys.iter().enumerate() {
            let wy = if j == 0 { 1.0 - fy } else { fy };
            for (i, &xx) in xs.iter().enumerate() {
                let w = wy * if i == 0 { 1.0 - fx } else { fx };
                let v = self.decode(level, yy * level.width as usize + xx);
                for c in 0..4 {
                    out[c] += w * v[c];
                }
            }
        }
        out
    }

    fn decode(&self, level: &Level, i: usize) -> [f32; 4] {
        match self.encoding {
            Encoding::SrgbAlpha => {
                let t = &level.texels[4 * i..4 * i + 4];
                let lut = srgb_lut();
                [
                    lut[t[0] as usize],
                    lut[t[1] as usize],
                    lut[t[2] as usize],
                    t[3] as f32 / 255.0,
                ]
            }
            Encoding::Linear8 => [level.texels[i] as f32 / 255.0, 0.0, 0.0, 0.0],
        }
    }
}

fn srgb_lut() -> &'static [f32; 256] {
    static LUT: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    LUT.get_or_init(srgb_table)
}

/// Number of levels of a `width`×`height` chain down to 1×1.
pub fn level_count(width: u32, height: u32) -> usize {
    (32 - width.max(height).max(1).leading_zeros()) as usize
}

/// The albedo chain of `tex`: level 0 as stored, each further level the linear-space box mean.
pub fn albedo_chain(tex: &Texture) -> MipChain {
    let lut = srgb_lut();
    let mut levels = vec![Level {
        width: tex.width,
        height: tex.height,
        texels: tex.texels.clone(),
    }];
    // Linear RGBA of the current level, kept in f32 so rounding does not accumulate.
    let mut linear: Vec<[f32; 4]> = tex
        .texels
        .chunks_exact(4)
        .map(|t| {
            [
                lut[t[0] as usize],
                lut[t[1] as usize],
                lut[t[2] as usize],
                t[3] as f32 / 255.0,
            ]
        })
        .collect();
    let (mut w, mut h) = (tex.width, tex.height);
    for _ in 1..level_count(tex.width, tex.height) {
        let (nw, nh, next) = box_down(&linear, w, h);
        let texels = next
            .iter()
            .flat_map(|p| {
                [
                    to_byte(linear_to_srgb(p[0])),
                    to_byte(linear_to_srgb(p[1])),
                    to_byte(linear_to_srgb(p[2])),
                    to_byte(p[3]),
                ]
            })
            .collect();
        levels.push(Level {
            width: nw,
            height: nh,
            texels,
        });
        (w, h, linear) = (nw, nh, next);
    }
    MipChain {
        encoding: Encoding::SrgbAlpha,
        levels,
    }
}

/// The mask chain of `mask` reading `channel` of `tex`, coverage-preserving below level 0.
pub fn mask_chain(tex: &Texture, mask: &AlphaMask, channel: Channel) -> MipChain {
    let values: Vec<[f32; 4]> = tex
        .texels
        .chunks_exact(4)
        .map(|t| {
            let v =
                (mask.factor * channel_value([t[0], t[1], t[2], t[3]], channel)).clamp(0.0, 1.0);
            [v, 0.0, 0.0, 0.0]
        })
        .collect();
    let level0: Vec<u8> = values.iter().map(|v| to_byte(v[0])).collect();
    let coverage = coverage_of(level0.iter().map(|&b| b as f32 / 255.0), mask.cutoff);
    let mut levels = vec![Level {
        width: tex.width,
        height: tex.height,
        texels: level0,
    }];
    let (mut w, mut h, mut raw) = (tex.width, tex.height, values);
    for _ in 1..level_count(tex.width, tex.height) {
        let (nw, nh, next) = box_down(&raw, w, h);
        let scale = coverage_scale(&next, mask.cutoff, coverage);
        levels.push(Level {
            width: nw,
            height: nh,
            texels: next.iter().map(|v| to_byte(v[0] * scale)).collect(),
        });
        (w, h, raw) = (nw, nh, next);
    }
    MipChain {
        encoding: Encoding::Linear8,
        levels,
    }
}

/// Fraction of `values` at or above `cutoff`.
fn coverage_of(values: impl Iterator<Item = f32>, cutoff: f32) -> f64 {
    let (mut n, mut on) = (0usize, 0usize);
    for v in values {
        n += 1;
        on += (v >= cutoff) as usize;
    }
    on as f64 / n.max(1) as f64
}

/// The scale of `values` whose quantised coverage at `cutoff` is closest to `target`
/// (bisection: coverage grows with the scale).
fn coverage_scale(values: &[[f32; 4]], cutoff: f32, target: f64) -> f32 {
    let cover = |s: f32| {
        coverage_of(
            values.iter().map(|v| to_byte(v[0] * s) as f32 / 255.0),
            cutoff,
        )
    };
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    while cover(hi) < target && hi < 1024.0 {
        hi *= 2.0;
    }
    for _ in 0..24 {
        let mid = 0.5 * (lo + hi);
        if cover(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // The two ends of the final bracket straddle the target: keep the closer one.
    if (cover(lo) - target).abs() < (cover(hi) - target).abs() {
        lo
    } else {
        hi
    }
}

/// The 2×2 box mean of a `w`×`h` image (an odd last row or column averages with itself).
fn box_down(src: &[[f32; 4]], w: u32, h: u32) -> (u32, u32, Vec<[f32; 4]>) {
    let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
    let at = |x: u32, y: u32| src[(y.min(h - 1) * w + x.min(w - 1)) as usize];
    let out = (0..nh)
        .into_par_iter()
        .flat_map_iter(|y| {
            (0..nw).map(move |x| {
                let q = [
                    at(2 * x, 2 * y),
                    at(2 * x + 1, 2 * y),
                    at(2 * x, 2 * y + 1),
                    at(2 * x + 1, 2 * y + 1),
                ];
                std::array::from_fn(|c| 0.25 * (q[0][c] + q[1][c] + q[2][c] + q[3][c]))
            })
        })
        .collect();
    (nw, nh, out)
}

fn to_byte(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Drop leading levels until no side exceeds `max_size`.
fn skip_to_fit(mut chain: MipChain, max_size: u32) -> MipChain {
    let fits = |l: &Level| l.width <= max_size && l.height <= max_size;
    let first = chain
        .levels
        .iter()
        .position(fits)
        .unwrap_or(chain.levels.len() - 1);
    chain.levels.drain(..first);
    chain
}
