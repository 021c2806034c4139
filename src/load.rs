//! Loading a pipeline's input (scene or height map) and summarising it for `relume-bake load`.

pub mod themes;

use crate::error::{Error, Result};
use crate::heightmap::{load_heightmap, HeightMap, HeightMapInfo, HeightMapOptions};
use crate::pipeline::Input;
use crate::scene::freeform::{FreeformScene, HeightGrid};
use crate::scene::{load_scene, LoadWarnings, Scene, SceneOptions};
use serde::Serialize;
use std::path::Path;

/// A loaded input with what its loader noticed.
pub enum LoadedInput {
    Scene(Scene, LoadWarnings),
    HeightMap(HeightMap, HeightMapInfo),
}

/// Load the input a pipeline names.
pub fn load_input(input: &Input) -> Result<LoadedInput> {
    match input {
        Input::Scene(s) => {
            let (mut scene, warnings) = load_scene(&s.path, s.options())?;
            for (k, l) in s.lights.iter().enumerate() {
                let light = l
                    .to_light(&format!("pipeline light {k}"))
                    .map_err(Error::knob)?;
                scene.lights.push(light);
            }
            Ok(LoadedInput::Scene(scene, warnings))
        }
        Input::HeightMap(h) => {
            let (map, info) = load_heightmap(&h.path, &h.options())?;
            Ok(LoadedInput::HeightMap(map, info))
        }
    }
}

/// Is this path a scene (by extension)?
pub fn is_scene_path(path: &Path) -> bool {
    matches!(
        path.extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref(),
        Some("obj") | Some("gltf") | Some("glb")
    )
}

/// Summary of a scene for people and `--json`.
#[derive(Clone, Debug, Serialize)]
pub struct SceneSummary {
    pub kind: &'static str,
    pub path: String,
    pub vertices: usize,
    pub triangles: usize,
    pub degenerate_triangles: usize,
    pub objects: Vec<String>,
    pub materials: Vec<crate::scene::Material>,
    /// Each material's mean albedo over its texture (its albedo when untextured).
    pub mean_albedos: Vec<[f32; 3]>,
    /// The textures, `name width×height` (materials refer to them by index).
    pub textures: Vec<String>,
    pub lights: Vec<crate::scene::Light>,
    pub bounds_min: [f32; 3],
    pub bounds_max: [f32; 3],
    pub total_area: f64,
    pub grey: bool,
    pub warnings: Vec<String>,
}

/// Summary of a height map for people and `--json`.
#[derive(Clone, Debug, Serialize)]
pub struct HeightMapSummary {
    pub kind: &'static str,
    pub path: String,
    pub width: usize,
    pub height: usize,
    pub cell_size: [f64; 2],
    pub cell_size_source: String,
    pub height_scale: f64,
    pub min: f32,
    pub max: f32,
    pub nodata_count: usize,
    pub format: String,
    pub sample: String,
}

/// The theme set a freeform scene names (`themes.file`, relative to the scene file at
/// `path`), loaded; `None` when the scene has no themes.
pub fn freeform_themes(
    path: &Path,
    scene: &FreeformScene,
) -> Result<Option<crate::theme::ThemeSet>> {
    match &scene.themes {
        Some(t) => {
            let file = path.parent().unwrap_or(Path::new(".")).join(&t.file);
            themes::load_themes(&file, None).map(Some)
        }
        None => Ok(None),
    }
}

/// Read a freeform scene and the height maps its shape textures name (paths relative to the
/// scene file; any height-map format, box-filtered by the grid's `downsample`), replacing each
/// file grid by its samples.
pub fn freeform_scene(path: &Path) -> Result<FreeformScene> {
    let mut scene = FreeformScene::load(path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    for (i, t) in scene.shape.textured_mut().into_iter().enumerate() {
        for grid in std::iter::once(&mut t.heights).chain(t.morph_to.as_mut()) {
            if let HeightGrid::File {
                path: file,
                downsample,
            } = grid
            {
                let opts = HeightMapOptions {
                    downsample: *downsample,
                    ..HeightMapOptions::default()
                };
                let (map, _) = load_heightmap(&dir.join(&*file), &opts)?;
                *grid = HeightGrid::Grid {
                    width: map.width,
                    height: map.height,
                    values: map.heights,
                };
            }
        }
        t.check().map_err(|m| {
            Error::input(
                path,
                format!("shape texture {} (in file order): {m}", i + 1),
            )
        })?;
    }
    Ok(scene)
}

/// Summarise a loaded scene.
pub fn summarize_scene(path: &Path, scene: &Scene, warnings: &LoadWarnings) -> SceneSummary {
    let (lo, hi) = scene.bounds();
    SceneSummary {
        kind: "scene",
        path: path.display().to_string(),
        vertices: scene.positions.len(),
        triangles: scene.triangles.len(),
        degenerate_triangles: scene.degenerate_triangles().count(),
        objects: scene.objects.clone(),
        materials: scene.materials.clone(),
        mean_albedos: scene.mean_albedos(),
        textures: scene
            .textures
            .iter()
            .map(|t| format!("{} {}×{}", t.name, t.width, t.height))
            .collect(),
        lights: scene.lights.clone(),
        bounds_min: lo.to_array(),
        bounds_max: hi.to_array(),
        total_area: scene.total_area(),
        grey: scene.is_grey(),
        warnings: warnings.messages.clone(),
    }
}

/// Summarise a loaded height map.
pub fn summarize_heightmap(path: &Path, map: &HeightMap, info: &HeightMapInfo) -> HeightMapSummary {
    let (min, max) = map.min_max();
    HeightMapSummary {
        kind: "heightmap",
        path: path.display().to_string(),
        width: map.width,
        height: map.height,
        cell_size: map.cell_size,
        cell_size_source: info.cell_size_source.clone(),
        height_scale: map.height_scale,
        min,
        max,
        nodata_count: info.nodata_count,
        format: info.format.clone(),
        sample: info.sample.clone(),
    }
}

/// Load a file for `relume-bake load`: a scene by extension, else a height map.
pub fn load_any(
    path: &Path,
    scene: SceneOptions,
    heightmap: &HeightMapOptions,
) -> Result<LoadedInput> {
    if is_scene_path(path) {
        let (s, w) = load_scene(path, scene)?;
        Ok(LoadedInput::Scene(s, w))
    } else if path.extension().is_none() {
        Err(Error::unsupported(path, "no file extension: cannot tell the format (scenes: .obj .gltf .glb; height maps: .png .jpg .exr .tif .raw)"))
    } else {
        let (m, i) = load_heightmap(path, heightmap)?;
        Ok(LoadedInput::HeightMap(m, i))
    }
}

impl SceneSummary {
    /// The summary as text for people (`relume-bake load`).
    pub fn to_text(&self) -> String {
        let mut t = format!(
            "scene      {}\ntriangles  {} ({} degenerate), vertices {}\nobjects    {}\nmaterials  {}\n",
            self.path,
            self.triangles,
            self.degenerate_triangles,
            self.vertices,
            self.objects.join(", "),
            self.materials.len()
        );
        for (m, mean) in self.materials.iter().zip(&self.mean_albedos) {
            t += &format!(
                "  {:<16} albedo {:?}  emission {:?}\n",
                m.name, m.albedo, m.emission
            );
            if let Some(r) = &m.albedo_texture {
                t += &format!(
                    "  {:<16} × texture {} (mean albedo {:.3?})\n",
                    "", self.textures[r.texture as usize], mean
                );
            }
            if let Some(a) = &m.alpha {
                let what = match &a.texture {
                    Some((r, ch)) => format!("{:?} of {}", ch, self.textures[r.texture as usize]),
                    None => "no texture".into(),
                };
                t += &format!(
                    "  {:<16} alpha mask: {} × {what}, cut below {}\n",
                    "", a.factor, a.cutoff
                );
            }
        }
        t += &format!("lights     {}\n", self.lights.len());
        for l in &self.lights {
            t += &format!(
                "  {:<16} {:?} intensity {} colour {:?}\n",
                l.name, l.kind, l.intensity, l.color
            );
        }
        t += &format!(
            "bounds     {:?} .. {:?}\narea       {:.6}\ngrey       {}\n",
            self.bounds_min, self.bounds_max, self.total_area, self.grey
        );
        t
    }
}

impl HeightMapSummary {
    /// The summary as text for people (`relume-bake load`).
    pub fn to_text(&self) -> String {
        format!(
            "height map {} ({} {})\nsize       {} x {}\ncell size  {} x {} m ({})\nheights    {} .. {} m (height scale {})\nno-data    {}\n",
            self.path,
            self.format,
            self.sample,
            self.width,
            self.height,
            self.cell_size[0],
            self.cell_size[1],
            self.cell_size_source,
            self.min,
            self.max,
            self.height_scale,
            self.nodata_count
        )
    }
}

/// The height map of a terrain command: a height-map file, or the height-map input of a pipeline
/// file (`.ron`) with its knobs; `cell_size` and `height_scale` override both.
pub fn heightmap_input(
    input: &Path,
    cell_size: Option<f64>,
    height_scale: Option<f64>,
) -> Result<HeightMap> {
    Ok(heightmap_input_with_info(input, cell_size, height_scale)?.0)
}

/// [`heightmap_input`] with what the loader learnt about the file (its georeference and
/// no-data texels).
pub fn heightmap_input_with_info(
    input: &Path,
    cell_size: Option<f64>,
    height_scale: Option<f64>,
) -> Result<(HeightMap, crate::heightmap::HeightMapInfo)> {
    let is_pipeline = input
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("ron"));
    let (path, mut opts) = if is_pipeline {
        let p = crate::pipeline::parse_pipeline(input)?;
        match &p.input {
            Input::HeightMap(h) => (h.path.clone(), h.options()),
            Input::Scene(_) => {
                return Err(Error::input(
                    input,
                    "this pipeline's input is a scene; terrain commands need a height map",
                ))
            }
        }
    } else {
        (input.to_path_buf(), HeightMapOptions::default())
    };
    if let Some(c) = cell_size {
        opts.cell_size = Some([c, c]);
    }
    if let Some(s) = height_scale {
        opts.height_scale = Some(s);
    }
    load_heightmap(&path, &opts)
}
