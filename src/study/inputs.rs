//! What a study measures on: the bundled defaults, a scene or pipeline named on the command
//! line, a bake, or a height map — loaded the same way `run` and the terrain commands load them.

use super::compression::{self, CompressionInput};
use crate::error::{Error, Result};
use crate::heightmap::HeightMap;
use crate::load::{load_input, LoadedInput};
use crate::pipeline::{parse_pipeline, Pipeline, Stage};
use crate::radiosity::formfactor::{Estimator, FormFactorParams};
use crate::radiosity::patches::voxelize::Resolution;
use crate::radiosity::transport::Bounces;
use crate::scene::{load_scene, Scene, SceneOptions};
use std::path::{Path, PathBuf};

/// A bundled file: relative to the current directory, else to the source tree relume was built
/// from.
pub fn bundled(rel: &str) -> Result<PathBuf> {
    let here = PathBuf::from(rel);
    if here.exists() {
        return Ok(here);
    }
    let built = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    if built.exists() {
        return Ok(built);
    }
    Err(Error::input(
        rel,
        "the bundled default input is not here nor in the source tree relume was built from; name an input explicitly",
    ))
}

/// Where a study's scene comes from: a pipeline (its input with its lights), a scene file, or
/// the bundled Cornell box.
#[derive(Clone, Debug, Default)]
pub struct SceneSource {
    pub pipeline: Option<PathBuf>,
    pub scene: Option<PathBuf>,
    pub scale: Option<f32>,
}

/// The scene to study, a description of it, and the pipeline when one was given. A pipeline's
/// scene is loaded exactly as `run` loads it (with the pipeline's `lights`).
pub fn scene(src: &SceneSource) -> Result<(Scene, String, Option<Pipeline>)> {
    if let Some(p) = &src.pipeline {
        let pipeline = parse_pipeline(p)?;
        let LoadedInput::Scene(scene, _) = load_input(&pipeline.input)? else {
            return Err(Error::input(
                p,
                "this pipeline's input is a height map; the radiosity and compression studies need a scene",
            ));
        };
        return Ok((
            scene,
            format!("the scene of {}", p.display()),
            Some(pipeline),
        ));
    }
    let (path, scale) = match &src.scene {
        Some(s) => (s.clone(), src.scale.unwrap_or(1.0)),
        None => (bundled("scenes/cornell-box/cornell_box.obj")?, 0.001),
    };
    let (scene, _) = load_scene(&path, SceneOptions { scale })?;
    Ok((scene, format!("{} (scale {scale})", path.display()), None))
}

/// The compression study's matrix: a bake's, or one baked from the scene with the pipeline's
/// (else default) knobs; `patches` overrides the patch target.
pub fn compression_input(
    baked: Option<&Path>,
    src: &SceneSource,
    patches: Option<u32>,
    quick: bool,
) -> Result<CompressionInput> {
    if let Some(dir) = baked {
        return compression::input_from_bake(dir);
    }
    let (scene, name, pipeline) = scene(src)?;
    let mut resolution = Resolution::TargetPatches(if quick { 300 } else { 1000 });
    let mut ff = FormFactorParams {
        estimator: Estimator::Hemisphere,
        samples: if quick { 512 } else { 4096 },
        seed: 0,
    };
    let mut bounces = Bounces::Infinite;
    for stage in pipeline.iter().flat_map(|p| &p.stages) {
        match stage {
            Stage::Voxelize(k) => resolution = k.resolution,
            Stage::FormFactors(k) => ff = k.params(),
            Stage::Transport(k) => bounces = k.bounces,
            _ => {}
        }
    }
    if let Some(n) = patches {
        resolution = Resolution::TargetPatches(n);
    }
    compression::input_from_scene(&scene, resolution, &ff, bounces, &name)
}

/// The terrain study's height map (a file, a pipeline's, else bundled Puget Sound) and its
/// description.
pub fn heightmap(
    file: Option<&Path>,
    pipeline: Option<&Path>,
    cell_size: Option<f64>,
    height_scale: Option<f64>,
) -> Result<(HeightMap, String)> {
    let (input, name) = match (file, pipeline) {
        (Some(h), _) => (h.to_path_buf(), h.display().to_string()),
        (None, p) => {
            let p = match p {
                Some(p) => p.to_path_buf(),
                None => bundled("pipelines/puget-sound.ron")?,
            };
            let name = format!("the height map of {}", p.display());
            (p, name)
        }
    };
    let map = crate::load::heightmap_input(&input, cell_size, height_scale)?;
    let name = format!(
        "{name}: {}x{}, cell {} x {} m",
        map.width, map.height, map.cell_size[0], map.cell_size[1]
    );
    Ok((map, name))
}
