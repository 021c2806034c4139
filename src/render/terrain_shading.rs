//! The CPU twin of the terrain shading in `shaders/terrain_render.wgsl`: the same hypsometric
//! tint, the same texel radiance (Lambert from `terrain::hard::relief::lambert`, the relief-shadow paper's shadow
//! brightness k_shadow) and the same tone map, evaluated per texel — what the GPU shows in the
//! top-down map view, pixel for texel.

use super::tonemap::{to_u8, tonemap};
use crate::heightmap::HeightMap;
use crate::terrain::hard::relief::{k_shadow, lambert};
use crate::terrain::sun::Sun;
use crate::theme::ThemeSet;
use serde::{Deserialize, Serialize};

/// Display knobs of a terrain frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TerrainSettings {
    pub exposure: f32,
    /// Shadow brightness in a full shadow when the sun is at the horizon / at the zenith.
    pub k_dark: f32,
    pub k_bright: f32,
    /// Multiplies heights for display (1 = true scale).
    pub vertical_exaggeration: f32,
    pub shadows: bool,
    /// Soft shadows of the sun's disc (branch-and-bound) instead of hard ones.
    pub soft: bool,
    /// Hard shadows from the horizon maps (O(1) per pixel, interpolated between stored
    /// azimuths) when the bake has them, instead of the traversal over the min/max mipmap.
    pub horizon: bool,
    /// Thematic textures (docs/themes.md) instead of the hypsometric tint when the bake has a
    /// theme set.
    pub themes: bool,
    /// Scattered light on the terrain and in the sky (docs/atmosphere.md): the constant-density
    /// fog of Vyatkin et al. (2018) per vertex or per pixel, Hillaire's tables, or none.
    pub atmosphere: crate::atmosphere::Model,
    /// Sun irradiance scale.
    pub sun_strength: f32,
    pub background: [f32; 3],
}

impl Default for TerrainSettings {
    fn default() -> Self {
        TerrainSettings {
            exposure: 1.5,
            k_dark: 0.25,
            k_bright: 0.6,
            vertical_exaggeration: 3.0,
            shadows: true,
            soft: false,
            horizon: true,
            themes: true,
            atmosphere: crate::atmosphere::Model::Hillaire,
            sun_strength: 1.0,
            background: [0.55, 0.65, 0.8],
        }
    }
}

/// Hypsometric tint (linear RGB) at relative height t ∈ [0, 1]: twin of `tint`.
pub fn tint(t: f32) -> [f32; 3] {
    let t = t.clamp(0.0, 1.0);
    let low = [0.10, 0.25, 0.08];
    let mid = [0.35, 0.30, 0.18];
    let high = [0.80, 0.80, 0.80];
    let mix = |a: [f32; 3], b: [f32; 3], s: f32| [0, 1, 2].map(|c| a[c] * (1.0 - s) + b[c] * s);
    if t < 0.5 {
        mix(low, mid, t * 2.0)
    } else {
        mix(mid, high, t * 2.0 - 1.0)
    }
}

/// Radiance of a texel of `albedo` before fog: twin of `texel_radiance`.
pub fn texel_radiance(
    s: &TerrainSettings,
    albedo: [f32; 3],
    lambert: f32,
    shadow: f32,
    k: f32,
) -> [f32; 3] {
    let relief = lambert * (1.0 - (1.0 - k) * shadow);
    albedo.map(|c| c * (s.sun_strength * relief + 0.15))
}

/// The map view (one pixel per texel, north up, no fog) of `map` under `sun` with per-texel
/// shadowed fraction `shadow` (1 = hard shadow), textured by `themes` when given (animation
/// frame `frame`) and `s.themes`, else by the hypsometric tint.
pub fn map_view(
    map: &HeightMap,
    sun: &Sun,
    shadow: &[f32],
    s: &TerrainSettings,
    themes: Option<(&ThemeSet, u32)>,
) -> image::RgbaImage {
    let lookup = themes.filter(|_| s.themes).map(|(t, f)| t.lookup(f));
    // The index map spans the height map: texel centre → index texels.
    let scale = lookup.as_ref().map_or([1.0; 2], |l| {
        let base = &l.set.index.levels[0];
        [
            base.width as f32 / map.width as f32,
            base.height as f32 / map.height as f32,
        ]
    });
    let lam = lambert(map, sun);
    let k = k_shadow(sun, s.k_dark as f64, s.k_bright as f64) as f32;
    let (lo, hi) = map.min_max();
    let span = (hi - lo).max(1e-6);
    let mut img = image::RgbaImage::new(map.width as u32, map.height as u32);
    for (i, px) in img.pixels_mut().enumerate() {
        let sh = if s.shadows { shadow[i] } else { 0.0 };
        let albedo = match &lookup {
            Some(l) => {
                let p = [
                    ((i % map.width) as f32 + 0.5) * scale[0],
                    ((i / map.width) as f32 + 0.5) * scale[1],
                ];
                l.albedo(p, scale[0].max(scale[1]))
            }
            None => tint((map.heights[i] - lo) / span),
        };
        let c = tonemap(texel_radiance(s, albedo, lam[i], sh, k), s.exposure);
        *px = image::Rgba([to_u8(c[0]), to_u8(c[1]), to_u8(c[2]), 255]);
    }
    img
}
