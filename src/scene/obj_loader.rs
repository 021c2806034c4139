//! Wavefront OBJ + MTL through `tobj`: polygons triangulated as fans, `Kd` → albedo factor,
//! `map_Kd` → albedo texture, `d` and `map_d` → alpha mask (cut out below 0.5), `Ke` → emitted
//! radiance. `Tr` is ignored (exporters disagree on whether it is `d` or `1 − d`).
//!
//! Files in the wild ([`super::mtl`]): texture options before the file name, backslashes, names
//! whose case differs from the file on disk (found case-insensitively, with a warning naming
//! both). A missing MTL or texture is a warning and the factor alone; a texture that exists but
//! cannot be decoded is an error naming it. Texture coordinates are flipped to glTF's frame
//! (`v ← 1 − v`); a textured material on an object without `vt` loses its texture, with a warning.

use super::mtl::{self, TextureStatement};
use super::texture::{AlphaMask, Channel, Texture};
use super::{LoadWarnings, Material, Scene};
use crate::error::{Error, Result};
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

pub(super) fn load(path: &Path, warnings: &mut LoadWarnings) -> Result<Scene> {
    // tobj reports a missing file as a parse failure; check readability first for a clear I/O error.
    std::fs::metadata(path).map_err(|e| Error::io(path, "cannot read scene", e))?;
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, materials) = tobj::load_obj(path, &options)
        .map_err(|e| Error::input(path, format!("cannot parse OBJ: {e}")))?;

    let mut scene = Scene::default();
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let mut files = TextureFiles::default();
    let mtl: Vec<Material> = match materials {
        Ok(ms) => ms
            .iter()
            .map(|m| material(path, &dir, m, &mut files, warnings))
            .collect::<Result<_>>()?,
        Err(e) => {
            warnings.push(format!(
                "{}: material library could not be loaded ({e}); using a default grey material",
                path.display()
            ));
            Vec::new()
        }
    };
    scene.textures = files.decode()?;
    let any_uv = models.iter().any(|m| !m.mesh.texcoords.is_empty());
    for model in &models {
        let mesh = &model.mesh;
        if mesh.indices.is_empty() {
            continue;
        }
        let mut material = match mesh.material_id.and_then(|id| mtl.get(id)) {
            Some(m) => m.clone(),
            None => Material::default_grey(),
        };
        let has_uv = !mesh.texcoords.is_empty();
        if !has_uv && material.is_textured() {
            warnings.push(format!(
                "{}: object `{}` has textured material `{}` but no texture coordinates (vt); using its colour factor alone",
                path.display(),
                model.name,
                material.name
            ));
            material.albedo_texture = None;
            material.alpha = material.alpha.filter(|a| a.texture.is_none());
        }
        let material = scene.material_index(material);
        let object = scene.objects.len() as u32;
        scene.objects.push(if model.name.is_empty() {
            "unnamed".into()
        } else {
            model.name.clone()
        });
        let base = scene.positions.len() as u32;
        if mesh.positions.len() % 3 != 0 {
            return Err(Error::input(
                path,
                "cannot parse OBJ: truncated vertex data",
            ));
        }
        let count = mesh.positions.len() / 3;
        scene
            .positions
            .extend(mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        if any_uv {
            if has_uv && mesh.texcoords.len() != 2 * count {
                return Err(Error::input(
                    path,
                    format!(
                        "cannot parse OBJ: object `{}` has {} texture coordinates for {count} vertices",
                        model.name,
                        mesh.texcoords.len() / 2
                    ),
                ));
            }
            if has_uv {
                let uv = mesh.texcoords.chunks_exact(2);
                scene.uvs.extend(uv.map(|t| [t[0], 1.0 - t[1]]));
            } else {
                scene.uvs.extend(std::iter::repeat_n([0.0; 2], count));
            }
        }
        if mesh.indices.len() % 3 != 0 {
            return Err(Error::input(
                path,
                format!(
                    "cannot parse OBJ: object `{}` has an incomplete face",
                    model.name
                ),
            ));
        }
        for t in mesh.indices.chunks_exact(3) {
            scene
                .triangles
                .push([base + t[0], base + t[1], base + t[2]]);
            scene.triangle_material.push(material);
            scene.triangle_object.push(object);
        }
    }
    if scene.triangles.is_empty() {
        return Err(Error::input(
            path,
            "the OBJ file has no faces (is it empty or truncated?)",
        ));
    }
    Ok(scene)
}

/// One MTL material: factors from `Kd`, `d`, `Ke`; textures from `map_Kd`, `map_d`.
fn material(
    obj: &Path,
    dir: &Path,
    m: &tobj::Material,
    files: &mut TextureFiles,
    warnings: &mut LoadWarnings,
) -> Result<Material> {
    let mut statement =
        |key: &str, value: &Option<String>| -> Result<Option<(TextureStatement, u32)>> {
            let Some(value) = value else { return Ok(None) };
            let st = mtl::parse_statement(value).map_err(|e| {
                Error::input(obj, format!("material `{}`: `{key} {value}`: {e}", m.name))
            })?;
            Ok(files.find(dir, &st, warnings).map(|index| (st, index)))
        };
    let albedo_texture = statement("map_Kd", &m.diffuse_texture)?.map(|(st, i)| st.reference(i));
    let mask = statement("map_d", &m.dissolve_texture)?.map(|(st, i)| {
        let channel = st.channel.unwrap_or(Channel::Luminance);
        (st.reference(i), channel)
    });
    let factor = m.dissolve.unwrap_or(1.0);
    let alpha = (mask.is_some() || factor < 1.0).then_some(AlphaMask {
        factor,
        texture: mask,
        cutoff: 0.5,
    });
    Ok(Material {
        name: m.name.clone(),
        albedo: m.diffuse.unwrap_or([0.5; 3]),
        emission: m.emissive.unwrap_or([0.0; 3]),
        albedo_texture,
        alpha,
    })
}

/// The texture files the materials name: found once each, decoded together at the end.
#[derive(Default)]
struct TextureFiles {
    /// Written name (relative to the MTL's folder) → path found on disk (None: missing, warned
    /// once).
    found: HashMap<String, Option<PathBuf>>,
    /// Distinct paths in first-use order; a texture's index is its position here.
    paths: Vec<PathBuf>,
}

impl TextureFiles {
    /// The index of the file `st` names (warning when it is missing, or found with another case).
    fn find(
        &mut self,
        dir: &Path,
        st: &TextureStatement,
        warnings: &mut LoadWarnings,
    ) -> Option<u32> {
        if !self.found.contains_key(&st.file) {
            let found = mtl::resolve(dir, &st.file);
            match &found {
                Some((path, true)) => warnings.push(format!(
                    "texture `{}` does not exist; using `{}` (the names differ in case)",
                    dir.join(&st.file).display(),
                    path.display()
                )),
                Some(_) => {}
                None => warnings.push(format!(
                    "texture `{}` does not exist; using the material's colour factor alone",
                    dir.join(&st.file).display()
                )),
            }
            self.found.insert(st.file.clone(), found.map(|(p, _)| p));
        }
        let path = self.found[&st.file].clone()?;
        Some(match self.paths.iter().position(|p| *p == path) {
            Some(i) => i as u32,
            None => {
                self.paths.push(path);
                (self.paths.len() - 1) as u32
            }
        })
    }

    /// Decode every file, in parallel; the first that fails is the error.
    fn decode(self) -> Result<Vec<Texture>> {
        self.paths.par_iter().map(|p| Texture::decode(p)).collect()
    }
}
