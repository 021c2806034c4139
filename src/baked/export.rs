//! Reading a bake out for other tools: patches as JSON, matrices as `.npy`, and the CPU gather
//! from the compressed transport.

use crate::error::{Error, Result};
use serde::Serialize;
use std::path::Path;

/// What `relume-bake export` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum ExportWhat {
    /// The patches as JSON.
    Patches,
    /// `form_factors.npy`.
    FormFactors,
    /// `transport.npy`.
    Transport,
    /// The scene with its baked lighting for a light setup, binary glTF ([`super::gltf`]).
    Gltf,
    /// Mean irradiance per scene object for a light setup, JSON
    /// ([`crate::radiosity::mesh::objects`]).
    Objects,
}

/// A standard light configuration of the encode report (`compress::report::standard_lights`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum StandardLight {
    Uniform,
    Random,
    Half,
    One,
}

#[derive(Serialize)]
pub struct PatchesJson {
    voxel_size: f64,
    origin: [f64; 3],
    grid: [u32; 3],
    patches: Vec<PatchJson>,
}

#[derive(Serialize)]
pub struct PatchJson {
    id: usize,
    area: f32,
    centroid: [f32; 3],
    normal: [f32; 3],
    axis: &'static str,
    voxel: [u32; 3],
    albedo: [f32; 3],
    emission: [f32; 3],
    objects: Vec<String>,
}

/// Export one file of a bake to `out`; returns the file's name.
pub fn export(dir: &Path, what: ExportWhat, out: &Path) -> Result<&'static str> {
    let manifest = super::Manifest::read(dir)?;
    let file = match what {
        ExportWhat::Patches => super::patches::FILE,
        ExportWhat::FormFactors => super::form_factors::FILE,
        ExportWhat::Transport => super::transport::FILE,
        ExportWhat::Gltf => {
            super::gltf::export_lit_glb(dir, &Default::default(), out)?;
            return Ok("gltf");
        }
        ExportWhat::Objects => {
            export_objects(dir, &Default::default(), out)?;
            return Ok("objects");
        }
    };
    if manifest.file(file).is_none() {
        return Err(Error::input(
            dir,
            format!("this bake has no `{file}`; run the stage that writes it first (see `relume-bake inspect`)"),
        ));
    }
    let src = dir.join(file);
    match what {
        ExportWhat::Patches => {
            let set = super::patches::read_file(&src)?;
            const AXES: [&str; 6] = ["+x", "-x", "+y", "-y", "+z", "-z"];
            let doc = PatchesJson {
                voxel_size: set.voxel_size,
                origin: set.origin,
                grid: set.dims,
                patches: set
                    .patches
                    .iter()
                    .enumerate()
                    .map(|(id, p)| PatchJson {
                        id,
                        area: p.area,
                        centroid: p.centroid,
                        normal: p.normal,
                        axis: AXES[p.axis as usize % 6],
                        voxel: p.voxel,
                        albedo: p.albedo,
                        emission: p.emission,
                        objects: p
                            .objects
                            .iter()
                            .map(|&o| set.objects.get(o as usize).cloned().unwrap_or_default())
                            .collect(),
                    })
                    .collect(),
            };
            let text = serde_json::to_string_pretty(&doc)
                .map_err(|e| Error::Internal(format!("cannot encode JSON: {e}")))?;
            std::fs::write(out, text).map_err(|e| Error::io(out, "cannot write", e))?;
        }
        _ => {
            let (shape, values) = super::npy::read_npy_f32(&src)?;
            super::npy::write_npy_f32(out, &shape, &values)?;
        }
    }
    Ok(file)
}

/// Per-object light of the bake in `dir` under `setup`, as JSON at `out`: for every scene
/// object its area and mean irradiance (corner-interpolated and from the patches) from light
/// that was reflected at least once or comes from an emitter — the punctual lights' direct
/// light is left out (the player evaluates it per pixel).
pub fn export_objects(
    dir: &Path,
    setup: &super::gltf::LitExport,
    out: &Path,
) -> Result<Vec<crate::radiosity::mesh::objects::ObjectLight>> {
    let lit = super::gltf::lit_patches(dir, setup)?;
    let visible = lit.raycast.visible(&lit.gpu_lights);
    let direct = if setup.settings.direct {
        crate::render::direct::object_direct(&lit.scene, &lit.gpu_lights, &|l, p, n, to, d| {
            !setup.settings.shadows || visible(l, p, n, to, d)
        })
    } else {
        vec![[0.0; 3]; lit.scene.objects.len()]
    };
    let objects: Vec<_> =
        crate::radiosity::mesh::objects::object_light(&lit.scene, &lit.set, &lit.b)
            .into_iter()
            .zip(direct)
            .map(|(o, d)| o.with_direct(d))
            .collect();
    let doc = serde_json::json!({ "transport": lit.transport, "objects": objects });
    let text = serde_json::to_string_pretty(&doc)
        .map_err(|e| Error::Internal(format!("cannot encode JSON: {e}")))?;
    super::images::write_atomic(out, |tmp| {
        std::fs::write(tmp, text).map_err(|e| Error::io(tmp, "cannot write", e))
    })?;
    Ok(objects)
}

/// Gather `B_ind = S·E` from the compressed transport of the bake in `dir` for a standard light
/// or the `[channels, n]` light in `light_npy`, and write it to `out` as `.npy`. Returns
/// (channels, n).
pub fn gather(
    dir: &Path,
    light: StandardLight,
    light_npy: Option<&Path>,
    out: &Path,
) -> Result<(usize, usize)> {
    let enc = super::encoded::read(dir)?;
    let (ch, n) = (enc.dense.channels, enc.dense.n);
    let e = match light_npy {
        Some(p) => {
            let (shape, data) = super::npy::read_npy_f32(p)?;
            if shape != [ch as u64, n as u64] && !(ch == 1 && shape == [n as u64]) {
                return Err(Error::input(
                    p,
                    format!("light has shape {shape:?}; this bake needs [{ch}, {n}]"),
                ));
            }
            data
        }
        None => {
            let name = match light {
                StandardLight::Uniform => "uniform",
                StandardLight::Random => "random",
                StandardLight::Half => "half",
                StandardLight::One => "one",
            };
            crate::compress::report::standard_lights(ch, n)
                .into_iter()
                .find(|(k, _)| k == name)
                .map(|(_, v)| v)
                .expect("standard light exists")
        }
    };
    let b = crate::compress::gather(&enc, &e);
    super::npy::write_npy_f32(out, &[ch as u64, n as u64], &b)?;
    Ok((ch, n))
}

/// Write one of the generated indoor scenes as `out` (OBJ, metres, y up) with its materials
/// beside it (the same stem, `.mtl`), both atomically; returns the scene and the `.mtl` path.
/// Precondition: `out` ends in `.obj` (`images::check_extension`).
pub fn write_generated_scene(
    which: crate::scene::generate::Generated,
    out: &Path,
) -> Result<(crate::scene::Scene, std::path::PathBuf)> {
    let scene = crate::scene::generate::generate(which);
    let mtl_path = out.with_extension("mtl");
    let mtl_name = mtl_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let header = format!(
        "{}: made by `relume-bake generate-scene {} --out FILE.obj` (metres, y up).",
        which.name(),
        which.name()
    );
    let (obj, mtl) = crate::scene::obj_writer::to_obj(&scene, &mtl_name, &header);
    for (path, text) in [(mtl_path.as_path(), &mtl), (out, &obj)] {
        crate::baked::images::write_atomic(path, |tmp| {
            std::fs::write(tmp, text).map_err(|e| Error::io(path, "cannot write", e))
        })?;
    }
    Ok((scene, mtl_path))
}
