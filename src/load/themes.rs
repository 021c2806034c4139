//! Loading a theme set (`THEMES.ron`, docs/themes.md): parse and check the description, read
//! what it names (height map, key image, GeoJSON polygons, PNG textures; paths relative to the
//! theme file) and assemble the [`ThemeSet`].

use crate::error::ron_located::{located, RonFormat};
use crate::error::{Error, IoContext, Result};
use crate::heightmap::georef::GeoReference;
use crate::heightmap::HeightMap;
use crate::theme::index_map::{self, IndexMap, Polygon, Rule};
use crate::theme::place::Placement;
use crate::theme::spec::{Coordinates, MapSpec, TextureSource, ThemeSpec};
use crate::theme::{Border, Class, ThemeSet, MAX_CLASSES};
use ron::extensions::Extensions;
use std::path::{Path, PathBuf};

const THEMES_FORMAT: RonFormat = RonFormat {
    reference: "docs/themes.md",
    planned: &[],
    variant_word: "map source",
    variant_enum: "MapSpec",
};

/// Parse and check theme-set text; `path` only names the file in messages.
pub fn parse_themes(path: &Path, text: &str) -> Result<ThemeSpec> {
    let options = ron::Options::default()
        .with_default_extension(Extensions::IMPLICIT_SOME | Extensions::UNWRAP_VARIANT_NEWTYPES);
    let spec: ThemeSpec = options
        .from_str(text)
        .map_err(|e| located(path, text, e, &THEMES_FORMAT))?;
    spec.check().map_err(|m| Error::input(path, m))?;
    Ok(spec)
}

/// A height map handed to the loader in place of the one the theme file names, with its
/// georeference: a pipeline's `Themes` stage passes the pipeline's, so that the classes follow
/// the baked relief texel for texel and georeferenced polygons land where the relief is.
#[derive(Clone, Copy, Debug)]
pub struct GivenHeightMap<'a> {
    pub map: &'a HeightMap,
    /// Its georeference (a GeoTIFF's tags, for the loaded grid), which places `LonLat` and
    /// `Map` polygons; None when it has none.
    pub georef: Option<&'a GeoReference>,
    /// What it is, for messages ("the pipeline's height map `dem.tif`").
    pub name: &'a str,
}

/// Load the theme set at `path`. `heightmap`, when given, is the height map a `Rules` map
/// classifies and whose georeference places `LonLat`/`Map` polygons, in place of the one the
/// file names.
pub fn load_themes(path: &Path, heightmap: Option<GivenHeightMap>) -> Result<ThemeSet> {
    let text = std::fs::read_to_string(path).at(path, "cannot read theme set")?;
    let spec = parse_themes(path, &text)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let (map, extra) = index_map_of(path, dir, &spec, heightmap)?;
    let pngs = spec
        .themes
        .iter()
        .map(|t| match &t.texture {
            TextureSource::Png(file) => read_texture(&dir.join(file), spec.texture_size).map(Some),
            TextureSource::Procedural(_) => Ok(None),
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(spec.assemble(map, extra, &pngs))
}

/// Check, before any work, that the theme set at `path` can be loaded over `heightmap`: that
/// polygons in `LonLat` or `Map` coordinates have the georeference they need (a pipeline calls
/// this for each `Themes` stage right after loading its input).
pub fn check_heightmap(path: &Path, heightmap: GivenHeightMap) -> Result<()> {
    let text = std::fs::read_to_string(path).at(path, "cannot read theme set")?;
    let spec = parse_themes(path, &text)?;
    if let MapSpec::Polygons {
        size, coordinates, ..
    } = &spec.map
    {
        let dir = path.parent().unwrap_or(Path::new("."));
        let grid = polygon_grid(path, dir, &spec.map, Some(heightmap))?;
        placement(path, *coordinates, *size, &grid)?;
    }
    Ok(())
}

/// The files a theme set reads (itself first, then what it names), for content-keyed
/// caching; a file that cannot be parsed lists only itself.
pub fn theme_files(path: &Path) -> Vec<PathBuf> {
    let mut out = vec![path.to_path_buf()];
    let Ok(text) = std::fs::read_to_string(path) else {
        return out;
    };
    let Ok(spec) = parse_themes(path, &text) else {
        return out;
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    match &spec.map {
        MapSpec::Rules {
            heightmap: Some(h), ..
        } => out.push(dir.join(h)),
        MapSpec::Image { path: p, .. } => out.push(dir.join(p)),
        MapSpec::Polygons {
            geojson, heightmap, ..
        } => out.extend(geojson.iter().chain(heightmap).map(|f| dir.join(f))),
        _ => {}
    }
    for t in &spec.themes {
        if let TextureSource::Png(p) = &t.texture {
            out.push(dir.join(p));
        }
    }
    out
}

/// What places the polygons of a `Polygons` map in `LonLat`/`Map` coordinates: the given height
/// map's georeference, else that of the file's `heightmap` (loaded here), with the height map's
/// size and its name for messages. None for other maps and coordinates.
type Grid = Option<(Option<GeoReference>, [usize; 2], String)>;

fn polygon_grid(
    path: &Path,
    dir: &Path,
    map: &MapSpec,
    given: Option<GivenHeightMap>,
) -> Result<Grid> {
    let MapSpec::Polygons {
        coordinates,
        heightmap,
        ..
    } = map
    else {
        return Ok(None);
    };
    if !coordinates.georeferenced() {
        return Ok(None);
    }
    Ok(Some(match (given, heightmap) {
        (Some(g), _) => (
            g.georef.cloned(),
            [g.map.width, g.map.height],
            g.name.to_string(),
        ),
        (None, Some(file)) => {
            let file = dir.join(file);
            let (m, info) = crate::load::heightmap_input_with_info(&file, None, None)?;
            let name = format!("the height map `{}`", file.display());
            (info.georef, [m.width, m.height], name)
        }
        (None, None) => {
            return Err(Error::input(
                path,
                format!(
                    "polygons in `{coordinates:?}` coordinates need a georeferenced height map: \
                     name one (`heightmap: \"dem.tif\"`, relative to this file, or a height-map \
                     pipeline), pass `--heightmap`, or bake the set in a height-map pipeline's \
                     `Themes` stage"
                ),
            ))
        }
    }))
}

/// The placement of polygon vertices on an index map of `size`; the error names the theme file,
/// the height map and why it cannot place them.
fn placement<'a>(
    path: &Path,
    coordinates: Coordinates,
    size: (usize, usize),
    grid: &'a Grid,
) -> Result<Placement<'a>> {
    let (georef, dims) = match grid {
        Some((g, dims, _)) => (g.as_ref(), *dims),
        None => (None, [1, 1]),
    };
    Placement::new(coordinates, size, (georef, dims)).map_err(|why| {
        let name = grid.as_ref().map_or("", |g| g.2.as_str());
        Error::input(
            path,
            format!("cannot place polygons in `{coordinates:?}` coordinates: {name} {why}"),
        )
    })
}

fn index_map_of(
    path: &Path,
    dir: &Path,
    spec: &ThemeSpec,
    given: Option<GivenHeightMap>,
) -> Result<(IndexMap, Vec<Class>)> {
    let theme = |name: &str| spec.theme_index(name).map_err(|m| Error::input(path, m));
    match &spec.map {
        MapSpec::Rules {
            heightmap,
            rules,
            otherwise,
        } => {
            let loaded;
            let map = match (heightmap, given) {
                (_, Some(m)) => m.map,
                (Some(file), None) => {
                    loaded = crate::load::heightmap_input(&dir.join(file), None, None)?;
                    &loaded
                }
                (None, None) => return Err(Error::input(
                    path,
                    "the `Rules` map names no `heightmap`: give one (a path relative to this file)",
                )),
            };
            let rules = rules
                .iter()
                .map(|r| {
                    Ok(Rule {
                        class: theme(&r.theme)?,
                        height: r.height,
                        slope: r.slope,
                        aspect: r.aspect,
                    })
                })
                .collect::<Result<Vec<_>>>()?;
            Ok((
                index_map::from_rules(map, &rules, theme(otherwise)?),
                vec![],
            ))
        }
        MapSpec::Image { path: file, keys } => {
            let file = dir.join(file);
            let img = crate::error::contain_panic(&file, "image", || image::open(&file))?
                .map_err(|e| Error::input(&file, format!("cannot read key image: {e}")))?
                .to_rgb8();
            let keys = keys
                .iter()
                .map(|(k, name)| {
                    Ok((
                        parse_hex(k).map_err(|m| Error::input(path, m))?,
                        theme(name)?,
                    ))
                })
                .collect::<Result<Vec<_>>>()?;
            let pixels: Vec<[u8; 3]> = img.pixels().map(|p| p.0).collect();
            let (w, h) = (img.width() as usize, img.height() as usize);
            index_map::from_keys(w, h, &pixels, &keys)
                .map(|m| (m, vec![]))
                .map_err(|(c, r, p)| {
                    Error::input(
                        &file,
                        format!(
                            "pixel ({c}, {r}) has colour #{:02x}{:02x}{:02x}, which no key of {} names",
                            p[0],
                            p[1],
                            p[2],
                            path.display()
                        ),
                    )
                })
        }
        MapSpec::Polygons {
            geojson,
            polygons,
            size,
            background,
            coordinates,
            ..
        } => {
            // The georeference first: a missing one stops the load before any file is read.
            let grid = polygon_grid(path, dir, &spec.map, given)?;
            let place = placement(path, *coordinates, *size, &grid)?;
            let mut list: Vec<(PathBuf, Feature)> = vec![];
            if let Some(file) = geojson {
                let file = dir.join(file);
                let features = read_geojson(&file)?;
                list.extend(features.into_iter().map(|f| (file.clone(), f)));
            }
            list.extend(polygons.iter().enumerate().map(|(k, p)| {
                let at = format!("polygon {k} of `polygons`");
                let f = (at, p.theme.clone(), p.border, p.rings.clone());
                (path.to_path_buf(), f)
            }));
            let mut extra: Vec<Class> = vec![];
            let base = spec.classes();
            let mut out = Vec::with_capacity(list.len());
            for (from, (at, name, border, rings)) in list {
                let t = theme(&name)?;
                let class = match border {
                    None => t,
                    Some(b) => {
                        b.check().map_err(|m| Error::input(path, m))?;
                        let c = Class {
                            border: b,
                            ..base[t as usize]
                        };
                        match extra.iter().position(|e| *e == c) {
                            Some(i) => (base.len() + i) as u8,
                            None => {
                                if base.len() + extra.len() >= MAX_CLASSES {
                                    return Err(Error::input(
                                        path,
                                        format!(
                                            "more than {MAX_CLASSES} theme/border combinations"
                                        ),
                                    ));
                                }
                                extra.push(c);
                                (base.len() + extra.len() - 1) as u8
                            }
                        }
                    }
                };
                let rings = rings
                    .into_iter()
                    .map(|r| r.into_iter().map(|p| place.texel(p)).collect())
                    .collect::<std::result::Result<_, String>>()
                    .map_err(|m| Error::input(&from, format!("{at}: {m}")))?;
                out.push(Polygon { class, rings });
            }
            Ok((
                index_map::rasterize(size.0, size.1, theme(background)?, &out),
                extra,
            ))
        }
    }
}

/// "#rrggbb" → bytes.
fn parse_hex(key: &str) -> std::result::Result<[u8; 3], String> {
    let hex = key.strip_prefix('#').unwrap_or(key);
    let bad = || format!("key `{key}` is not a colour; write \"#rrggbb\", e.g. \"#1e5aa0\"");
    if hex.len() != 6 {
        return Err(bad());
    }
    let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).map_err(|_| bad());
    Ok([byte(0)?, byte(2)?, byte(4)?])
}

/// Where a polygon came from ("feature 3"), its theme, its own border, its rings.
type Feature = (String, String, Option<Border>, Vec<Vec<[f64; 2]>>);

/// The polygons of a GeoJSON FeatureCollection: `Polygon` and `MultiPolygon` geometries, each
/// feature with a `theme` property and optionally `border`: {"kind": "fractal", "amplitude": 4,
/// "scale": 32} | {"kind": "natural"} | {"kind": "blend", "width": 3}.
fn read_geojson(path: &Path) -> Result<Vec<Feature>> {
    let text = std::fs::read_to_string(path).at(path, "cannot read GeoJSON")?;
    let bad = |m: String| Error::input(path, m);
    let v: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| bad(format!("not JSON: {e}")))?;
    let features = v["features"]
        .as_array()
        .ok_or_else(|| bad("expected a FeatureCollection with a `features` array".into()))?;
    let mut out = vec![];
    for (i, f) in features.iter().enumerate() {
        let at = |m: &str| bad(format!("feature {i}: {m}"));
        let theme = f["properties"]["theme"]
            .as_str()
            .ok_or_else(|| at("no string property `theme`"))?
            .to_string();
        let border = match &f["properties"]["border"] {
            serde_json::Value::Null => None,
            b => Some(border_of(b).map_err(|m| at(&m))?),
        };
        let g = &f["geometry"];
        let polys: Vec<&serde_json::Value> = match g["type"].as_str() {
            Some("Polygon") => vec![&g["coordinates"]],
            Some("MultiPolygon") => g["coordinates"]
                .as_array()
                .map(|a| a.iter().collect())
                .unwrap_or_default(),
            other => {
                return Err(at(&format!(
                    "geometry type {other:?}; only Polygon and MultiPolygon fill areas"
                )))
            }
        };
        for p in polys {
            let rings = p
                .as_array()
                .ok_or_else(|| at("coordinates are not an array of rings"))?
                .iter()
                .map(|ring| {
                    ring.as_array()
                        .ok_or_else(|| at("a ring is not an array"))?
                        .iter()
                        .map(|pt| match (pt[0].as_f64(), pt[1].as_f64()) {
                            (Some(x), Some(y)) if x.is_finite() && y.is_finite() => Ok([x, y]),
                            _ => Err(at("a position is not two finite numbers")),
                        })
                        .collect::<Result<Vec<_>>>()
                })
                .collect::<Result<Vec<_>>>()?;
            out.push((format!("feature {i}"), theme.clone(), border, rings));
        }
    }
    Ok(out)
}

fn border_of(b: &serde_json::Value) -> std::result::Result<Border, String> {
    let num = |k: &str| {
        b[k].as_f64()
            .map(|v| v as f32)
            .ok_or_else(|| format!("border needs a number `{k}`"))
    };
    match b["kind"].as_str() {
        Some("fractal") => Ok(Border::Fractal {
            amplitude: num("amplitude")?,
            scale: num("scale")?,
        }),
        Some("natural") => Ok(Border::Natural),
        Some("blend") => Ok(Border::Blend {
            width: num("width")?,
        }),
        k => Err(format!(
            "border kind {k:?}; expected \"fractal\", \"natural\" or \"blend\""
        )),
    }
}

/// A PNG theme texture, resampled to size² and decoded to linear RGB.
fn read_texture(path: &PathBuf, size: usize) -> Result<Vec<[f32; 3]>> {
    let img = crate::error::contain_panic(path, "image", || image::open(path))?
        .map_err(|e| Error::input(path, format!("cannot read theme texture: {e}")))?
        .to_rgb8();
    let img = if (img.width() as usize, img.height() as usize) == (size, size) {
        img
    } else {
        image::imageops::resize(
            &img,
            size as u32,
            size as u32,
            image::imageops::FilterType::Triangle,
        )
    };
    let lut = crate::theme::textures::srgb_table();
    Ok(img.pixels().map(|p| p.0.map(|c| lut[c as usize])).collect())
}
