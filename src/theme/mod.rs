//! Thematic textures (Vyatkin et al. 2018, §V; docs/themes.md): large
//! areas textured from little memory. A map of *class* indices (each class = a theme and a
//! border kind), a small tileable texture per theme, and a turbulence map that perturbs the
//! index lookup — borders come out fractal, and shifting the noise per frame animates them.
//!
//! Per texel, as Vyatkin et al. (2018) do ([`compose::albedo`], twin of `theme_albedo` in
//! `shaders/theme.wgsl`): read the border traits of the class at uv, scale uv by the border's
//! frequency, fetch the noise, multiply by the amplitude, offset uv, fetch the class index at
//! the offset uv, fetch its theme's texel (with a static in-region noise offset that breaks the
//! tiling).
//!
//! One file per piece: [`noise`] (the turbulence map), [`index_map`] (the class map from
//! height/slope/aspect rules, from an image, or rasterised from polygons), [`place`] (polygon
//! vertices from texels, the unit square, longitude/latitude or map coordinates to index
//! texels, through a height map's georeference), [`mip`] (index
//! levels that never blend: a coarser texel keeps what wholly covers it), [`ccc`] (Colour Cell
//! Compression of the index map, made lossless by an exception table), [`textures`] (the
//! procedural tileable theme textures and their mip chains), [`compose`] (the lookup and the
//! albedo at any resolution).

pub mod ccc;
pub mod compose;
pub mod index_map;
pub mod mip;
pub mod noise;
pub mod place;
pub mod spec;
pub mod textures;

use serde::{Deserialize, Serialize};

/// How the border of a class's region is drawn (the boundary kinds of Vyatkin et al. 2018).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Border {
    /// The index lookup is displaced by turbulence: `amplitude` in index-map texels (the most
    /// a border moves), `scale` the wavelength of the noise's first octave in index-map texels.
    Fractal { amplitude: f32, scale: f32 },
    /// The border stays where the map puts it (e.g. along streets or coasts traced exactly).
    Natural,
    /// A blend zone `width` index-map texels wide: the texel averages the themes found around
    /// it (beaches, forest edges).
    Blend { width: f32 },
}

impl Border {
    /// The GPU code of the kind (`theme.wgsl`: 0 fractal, 1 natural, 2 blend).
    pub fn kind_code(&self) -> u32 {
        match self {
            Border::Fractal { .. } => 0,
            Border::Natural => 1,
            Border::Blend { .. } => 2,
        }
    }

    /// Check the numbers (finite, non-negative; a fractal scale > 0).
    pub fn check(&self) -> Result<(), String> {
        match *self {
            Border::Fractal { amplitude, scale } => {
                if !(amplitude.is_finite() && amplitude >= 0.0) {
                    return Err(format!(
                        "a fractal border's amplitude must be ≥ 0 texels, got {amplitude}"
                    ));
                }
                if !(scale.is_finite() && scale > 0.0) {
                    return Err(format!(
                        "a fractal border's scale must be > 0 texels, got {scale}"
                    ));
                }
            }
            Border::Blend { width } if !(width.is_finite() && width >= 0.0) => {
                return Err(format!(
                    "a blend zone's width must be ≥ 0 texels, got {width}"
                ));
            }
            _ => {}
        }
        Ok(())
    }
}

/// How a theme's texture covers its regions.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tiling {
    /// Index-map texels per repeat of the theme texture.
    pub tile: f32,
    /// In-region noise: the texture lookup is displaced by up to `warp` repeats (0 = plain
    /// tiling), by noise of wavelength `warp_scale` index-map texels. Static (not animated).
    pub warp: f32,
    pub warp_scale: f32,
}

impl Tiling {
    /// Check the numbers (tile > 0, warp ≥ 0, warp_scale > 0, all finite).
    pub fn check(&self) -> Result<(), String> {
        let pos = |v: f32| v.is_finite() && v > 0.0;
        if pos(self.tile) && pos(self.warp_scale) && self.warp.is_finite() && self.warp >= 0.0 {
            Ok(())
        } else {
            Err(format!(
                "tiling needs tile > 0, warp ≥ 0 and warp_scale > 0 (got {}, {}, {})",
                self.tile, self.warp, self.warp_scale
            ))
        }
    }
}

impl Default for Tiling {
    fn default() -> Self {
        Tiling {
            tile: 8.0,
            warp: 0.35,
            warp_scale: 24.0,
        }
    }
}

/// One entry of the index map: which theme texture fills it and how its border looks.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Class {
    /// Index into the theme textures.
    pub theme: u32,
    pub border: Border,
    pub tiling: Tiling,
}

/// Most classes an index map can hold (indices are bytes; 255 is reserved).
pub const MAX_CLASSES: usize = 255;

/// Everything the lookup needs, as plain data.
#[derive(Clone, Debug)]
pub struct ThemeSet {
    /// Theme names, in texture order.
    pub themes: Vec<String>,
    pub classes: Vec<Class>,
    pub index: mip::IndexMips,
    pub textures: textures::ThemeTextures,
    pub noise: noise::TurbulenceMap,
    /// Animation: the border noise moves by `drift` noise periods per frame.
    pub drift: [f32; 2],
}

impl ThemeSet {
    /// A one-texel, one-theme set: what a renderer binds before a bake's themes are set.
    pub fn placeholder() -> ThemeSet {
        let class = Class {
            theme: 0,
            border: Border::Natural,
            tiling: Tiling::default(),
        };
        ThemeSet {
            themes: vec!["none".into()],
            classes: vec![class],
            index: mip::IndexMips::build(index_map::IndexMap::filled(1, 1, 0)),
            textures: textures::ThemeTextures::build(1, &[vec![[0.5; 3]]]),
            noise: noise::TurbulenceMap {
                size: 1,
                values: vec![[0.0; 2]],
            },
            drift: [0.0; 2],
        }
    }
}

/// What a theme set costs against a global albedo texture (bytes).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Memory {
    /// Index map, all levels, one byte per texel.
    pub index_raw: usize,
    /// Index map, all levels, Colour Cell Compressed (lossless with its exception table).
    pub index_ccc: usize,
    /// Blocks stored whole in the exception tables (over all levels).
    pub exception_blocks: usize,
    /// Theme textures with their mips (RGBA8).
    pub textures: usize,
    /// The turbulence map (two f32 per texel).
    pub noise: usize,
    /// index_ccc + textures + noise.
    pub total: usize,
    /// A global RGB8 texture at the index map's resolution, with mips (4/3).
    pub global_rgb8_index_res: usize,
    /// A global texture as detailed as the themes (theme texels per index texel = T/tile of
    /// the finest-tiled theme), with mips: RGB8 and BC1 (0.5 B/texel).
    pub global_rgb8_theme_res: usize,
    pub global_bc1_theme_res: usize,
}

impl ThemeSet {
    /// The index levels Colour Cell Compressed, finest first.
    pub fn compressed_levels(&self) -> Vec<ccc::Ccc> {
        self.index
            .levels
            .iter()
            .map(|m| ccc::Ccc::encode(m, true))
            .collect()
    }

    /// Bytes of the set against a global albedo texture.
    pub fn memory(&self) -> Memory {
        let ccc = self.compressed_levels();
        let base = &self.index.levels[0];
        let texels = (base.width * base.height) as f64;
        let finest = self
            .classes
            .iter()
            .map(|c| c.tiling.tile)
            .fold(f32::INFINITY, f32::min) as f64;
        let density = (self.textures.size as f64 / finest).max(1.0);
        let theme_res = texels * density * density * 4.0 / 3.0;
        let index_ccc: usize = ccc.iter().map(|c| c.bytes()).sum();
        let textures = self.textures.bytes();
        let noise = self.noise.values.len() * 8;
        Memory {
            index_raw: self.index.bytes(),
            index_ccc,
            exception_blocks: ccc.iter().map(|c| c.exceptions.len()).sum(),
            textures,
            noise,
            total: index_ccc + textures + noise,
            global_rgb8_index_res: (texels * 3.0 * 4.0 / 3.0) as usize,
            global_rgb8_theme_res: (theme_res * 3.0) as usize,
            global_bc1_theme_res: (theme_res * 0.5) as usize,
        }
    }
}
