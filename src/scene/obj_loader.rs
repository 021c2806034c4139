//! Wavefront OBJ + MTL through `tobj`: polygons triangulated as fans, `Kd` → albedo,
//! `Ke` → emitted radiance. A missing or unreadable MTL is a warning and a default grey material.

use super::{LoadWarnings, Material, Scene};
use crate::error::{Error, Result};
use std::path::Path;

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
    let mtl: Vec<Material> = match materials {
        Ok(ms) => ms
            .iter()
            .map(|m| Material {
                name: m.name.clone(),
                albedo: m.diffuse.unwrap_or([0.5; 3]),
                emission: m.emissive.unwrap_or([0.0; 3]),
            })
            .collect(),
        Err(e) => {
            warnings.push(format!(
                "{}: material library could not be loaded ({e}); using a default grey material",
                path.display()
            ));
            Vec::new()
        }
    };
    for model in &models {
        let mesh = &model.mesh;
        if mesh.indices.is_empty() {
            continue;
        }
        let material = match mesh.material_id.and_then(|id| mtl.get(id)) {
            Some(m) => m.clone(),
            None => Material::default_grey(),
        };
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
        scene
            .positions
            .extend(mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
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
