//! The description of a theme set (a `THEMES.ron` file, docs/themes.md) as plain data, its
//! checks, and the assembly of a [`ThemeSet`] once the loader has read what it names (height
//! map, images, polygons).

use super::index_map::{IndexMap, Range};
use super::mip::IndexMips;
use super::noise::{NoiseSettings, TurbulenceMap};
use super::textures::{procedural, Procedural, ThemeTextures};
use super::{Border, Class, ThemeSet, Tiling, MAX_CLASSES};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A theme set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Themes")]
pub struct ThemeSpec {
    pub themes: Vec<ThemeDef>,
    /// Where the index map comes from.
    pub map: MapSpec,
    /// Texels per side of every theme texture (a power of two, 4..=1024).
    #[serde(default = "default_texture_size")]
    pub texture_size: usize,
    #[serde(default)]
    pub noise: NoiseSpec,
    /// Border animation: noise periods the border noise moves per frame.
    #[serde(default = "default_drift")]
    pub drift: [f32; 2],
}

fn default_texture_size() -> usize {
    128
}
fn default_drift() -> [f32; 2] {
    [0.013, 0.007]
}

/// The turbulence map's knobs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default, rename = "Noise")]
pub struct NoiseSpec {
    pub size: usize,
    pub octaves: u32,
    pub base_period: u32,
    pub seed: u64,
}

impl Default for NoiseSpec {
    fn default() -> Self {
        let d = NoiseSettings::default();
        NoiseSpec {
            size: d.size,
            octaves: d.octaves,
            base_period: d.base_period,
            seed: d.seed,
        }
    }
}

/// One theme: its texture, the border its regions get, how its texture tiles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Theme")]
pub struct ThemeDef {
    pub name: String,
    pub texture: TextureSource,
    #[serde(default = "default_border")]
    pub border: Border,
    #[serde(default)]
    pub tiling: Tiling,
}

fn default_border() -> Border {
    Border::Fractal {
        amplitude: 4.0,
        scale: 48.0,
    }
}

/// A theme texture: made by relume, or a PNG (path relative to the theme file), resampled to
/// `texture_size`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum TextureSource {
    Procedural(Procedural),
    Png(String),
}

/// The index map's source.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum MapSpec {
    /// Rules over a height map (`heightmap` relative to the theme file, or a height-map
    /// pipeline; a pipeline's `Themes` stage uses the pipeline's height map instead). First
    /// matching rule wins.
    Rules {
        #[serde(default)]
        heightmap: Option<String>,
        rules: Vec<RuleSpec>,
        otherwise: String,
    },
    /// An image whose colours name themes: `keys: {"#1e5aa0": "water", "#808080": "rock"}`.
    Image {
        path: String,
        keys: BTreeMap<String, String>,
    },
    /// Polygons (a GeoJSON FeatureCollection with a `theme` property per feature, and an
    /// optional `border`; and/or inline polygons) rasterised at `size` over `background`.
    /// `heightmap` (relative to the theme file, or a height-map pipeline) is the georeferenced
    /// height map that places `LonLat` and `Map` coordinates; a pipeline's `Themes` stage uses
    /// the pipeline's height map instead.
    Polygons {
        #[serde(default)]
        geojson: Option<String>,
        #[serde(default)]
        polygons: Vec<PolygonSpec>,
        size: (usize, usize),
        background: String,
        #[serde(default)]
        coordinates: Coordinates,
        #[serde(default)]
        heightmap: Option<String>,
    },
}

/// A rule of [`MapSpec::Rules`]: height in metres, slope in degrees, aspect in degrees
/// clockwise from north (downhill; may wrap, e.g. (min: 300, max: 60)).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Rule")]
pub struct RuleSpec {
    pub theme: String,
    #[serde(default)]
    pub height: Option<Range>,
    #[serde(default)]
    pub slope: Option<Range>,
    #[serde(default)]
    pub aspect: Option<Range>,
}

/// An inline polygon: outline then holes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Polygon")]
pub struct PolygonSpec {
    pub theme: String,
    #[serde(default)]
    pub border: Option<Border>,
    pub rings: Vec<Vec<[f64; 2]>>,
}

/// How polygon coordinates are given.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Coordinates {
    /// Index-map texels, x east, y south, (0, 0) the north-west corner.
    #[default]
    Texels,
    /// The unit square, x east, y south.
    Unit,
    /// Longitude, latitude in degrees on WGS 84 (RFC 7946, the GeoJSON default), placed by the
    /// georeference of a geographic or UTM height map.
    LonLat,
    /// The georeferenced height map's own CRS (x, y in its units, e.g. UTM metres).
    Map,
}

impl Coordinates {
    /// Does this need a georeferenced height map?
    pub fn georeferenced(self) -> bool {
        matches!(self, Coordinates::LonLat | Coordinates::Map)
    }
}

impl ThemeSpec {
    /// Check everything that does not need a file; the message names the field.
    pub fn check(&self) -> Result<(), String> {
        if self.themes.is_empty() {
            return Err("`themes` is empty: a theme set needs at least one theme".into());
        }
        if self.themes.len() > MAX_CLASSES {
            return Err(format!(
                "{} themes; at most {MAX_CLASSES}",
                self.themes.len()
            ));
        }
        for (i, t) in self.themes.iter().enumerate() {
            if self.themes[..i].iter().any(|u| u.name == t.name) {
                return Err(format!("theme `{}` is defined twice", t.name));
            }
            t.border
                .check()
                .map_err(|m| format!("theme `{}`: {m}", t.name))?;
            t.tiling
                .check()
                .map_err(|m| format!("theme `{}`: {m}", t.name))?;
        }
        let s = self.texture_size;
        if !(s.is_power_of_two() && (4..=1024).contains(&s)) {
            return Err(format!(
                "texture_size must be a power of two in 4..=1024, got {s}"
            ));
        }
        let n = &self.noise;
        if !(4..=4096).contains(&n.size) || !(1..=12).contains(&n.octaves) || n.base_period == 0 {
            return Err(format!(
                "noise needs size in 4..=4096, octaves in 1..=12 and base_period ≥ 1 (got {}, {}, {})",
                n.size, n.octaves, n.base_period
            ));
        }
        if !self.drift.iter().all(|d| d.is_finite()) {
            return Err("drift must be finite".into());
        }
        for name in self.referenced() {
            self.theme_index(name)?;
        }
        if let MapSpec::Polygons {
            size,
            coordinates,
            heightmap,
            ..
        } = &self.map
        {
            if size.0 == 0 || size.1 == 0 || size.0 > 65536 || size.1 > 65536 {
                return Err(format!(
                    "polygons `size` must be 1..=65536 per side, got {}x{}",
                    size.0, size.1
                ));
            }
            if heightmap.is_some() && !coordinates.georeferenced() {
                return Err(format!(
                    "polygons in `{coordinates:?}` coordinates read no `heightmap` (it places \
                     `LonLat` and `Map` coordinates only): remove it, or give \
                     `coordinates: LonLat` or `Map`"
                ));
            }
        }
        Ok(())
    }

    fn referenced(&self) -> Vec<&str> {
        match &self.map {
            MapSpec::Rules {
                rules, otherwise, ..
            } => rules
                .iter()
                .map(|r| r.theme.as_str())
                .chain([otherwise.as_str()])
                .collect(),
            MapSpec::Image { keys, .. } => keys.values().map(|s| s.as_str()).collect(),
            MapSpec::Polygons {
                polygons,
                background,
                ..
            } => polygons
                .iter()
                .map(|p| p.theme.as_str())
                .chain([background.as_str()])
                .collect(),
        }
    }

    /// The index of theme `name` (class `i` of a theme set is theme `i` with its own border;
    /// polygons with a border of their own add classes after those).
    pub fn theme_index(&self, name: &str) -> Result<u8, String> {
        self.themes
            .iter()
            .position(|t| t.name == name)
            .map(|i| i as u8)
            .ok_or_else(|| {
                let known: Vec<&str> = self.themes.iter().map(|t| t.name.as_str()).collect();
                format!("no theme named `{name}` (themes: {})", known.join(", "))
            })
    }

    /// The default classes: one per theme, with the theme's border and tiling.
    pub fn classes(&self) -> Vec<Class> {
        self.themes
            .iter()
            .enumerate()
            .map(|(i, t)| Class {
                theme: i as u32,
                border: t.border,
                tiling: t.tiling,
            })
            .collect()
    }

    /// Assemble the set from the index map (built with [`ThemeSpec::classes`] plus `extra`
    /// classes) and the PNG textures the loader read (`pngs[i]` for theme i's `Png` source:
    /// linear RGB at `texture_size`²).
    pub fn assemble(
        &self,
        map: IndexMap,
        extra: Vec<Class>,
        pngs: &[Option<Vec<[f32; 3]>>],
    ) -> ThemeSet {
        let mut classes = self.classes();
        classes.extend(extra);
        let size = self.texture_size;
        let bases: Vec<Vec<[f32; 3]>> = self
            .themes
            .iter()
            .enumerate()
            .map(
                |(i, t)| match (&t.texture, pngs.get(i).and_then(|p| p.as_ref())) {
                    (_, Some(png)) => png.clone(),
                    (TextureSource::Procedural(kind), None) => {
                        procedural(*kind, size, self.noise.seed.wrapping_add(i as u64 * 7919))
                    }
                    (TextureSource::Png(_), None) => vec![[0.5; 3]; size * size],
                },
            )
            .collect();
        let n = self.noise;
        ThemeSet {
            themes: self.themes.iter().map(|t| t.name.clone()).collect(),
            classes,
            index: IndexMips::build(map),
            textures: ThemeTextures::build(size, &bases),
            noise: TurbulenceMap::generate(&NoiseSettings {
                size: n.size,
                octaves: n.octaves,
                base_period: n.base_period,
                seed: n.seed,
            }),
            drift: self.drift,
        }
    }
}
