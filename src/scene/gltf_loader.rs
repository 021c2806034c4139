//! glTF 2.0 (`.gltf` with external or embedded buffers, `.glb`) through the `gltf` crate.
//!
//! Node transforms are applied (negative-determinant transforms flip the winding back);
//! `baseColorFactor` × the mean linear colour of `baseColorTexture` → albedo;
//! `emissiveFactor` × `KHR_materials_emissive_strength` → emitted radiance;
//! `KHR_lights_punctual` directional, point and spot lights → [`Light`]s.

use super::{Light, LightKind, LoadWarnings, Material, Scene};
use crate::error::{Error, Result};
use glam::{Mat4, Vec3, Vec4};
use gltf::mesh::Mode;
use std::path::Path;

/// Load a glTF scene. The `gltf` crate 1.4 panics on many malformed files (unreachable code,
/// `unwrap`s and assertions in its readers, found by fuzzing: `fuzz/regressions/scene/`), so the
/// whole load runs under [`crate::error::contain_panic`]: a clear input error, never a crash.
pub(super) fn load(path: &Path, warnings: &mut LoadWarnings) -> Result<Scene> {
    crate::error::contain_panic(path, "glTF reader", || load_unguarded(path, warnings))?
}

fn load_unguarded(path: &Path, warnings: &mut LoadWarnings) -> Result<Scene> {
    check_accessor_indices(path)?;
    let (doc, buffers, images) = gltf::import(path).map_err(|e| describe(path, e))?;

    let mut scene = Scene::default();
    // Materials first so that indices are stable; glTF's default material (no `material`) is last.
    let mut material_ids = Vec::new();
    for m in doc.materials() {
        let pbr = m.pbr_metallic_roughness();
        let mut albedo = [0.0f32; 3];
        albedo.copy_from_slice(&pbr.base_color_factor()[..3]);
        if let Some(info) = pbr.base_color_texture() {
            let image = &images[info.texture().source().index()];
            let mean = mean_linear_rgb(image);
            for c in 0..3 {
                albedo[c] *= mean[c];
            }
        }
        let strength = m.emissive_strength().unwrap_or(1.0);
        let emission = m.emissive_factor().map(|e| e * strength);
        let name = m
            .name()
            .map(str::to_owned)
            .unwrap_or_else(|| format!("material{}", m.index().unwrap_or(0)));
        material_ids.push(scene.material_index(Material {
            name,
            albedo,
            emission,
        }));
    }

    let gltf_scene = doc.default_scene().or_else(|| doc.scenes().next());
    let Some(gltf_scene) = gltf_scene else {
        return Err(Error::input(path, "the glTF file has no scene"));
    };
    let mut stack: Vec<(gltf::Node, Mat4)> =
        gltf_scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    stack.reverse();
    while let Some((node, parent)) = stack.pop() {
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            let object = scene.objects.len() as u32;
            scene.objects.push(
                node.name()
                    .or(mesh.name())
                    .map(str::to_owned)
                    .unwrap_or_else(|| format!("mesh{}", mesh.index())),
            );
            let flip = world.determinant() < 0.0;
            for prim in mesh.primitives() {
                let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
                let Some(positions) = reader.read_positions() else {
                    warnings.push(format!(
                        "{}: a primitive of mesh `{}` has no positions; skipped",
                        path.display(),
                        scene.objects[object as usize]
                    ));
                    continue;
                };
                let base = scene.positions.len() as u32;
                let count = positions.len() as u32;
                scene
                    .positions
                    .extend(positions.map(|p| world.transform_point3(Vec3::from(p)).to_array()));
                let indices: Vec<u32> = match reader.read_indices() {
                    Some(ix) => ix.into_u32().collect(),
                    None => (0..count).collect(),
                };
                if let Some(&bad) = indices.iter().find(|&&i| i >= count) {
                    return Err(Error::input(
                        path,
                        format!(
                            "mesh `{}` has index {bad} but only {count} vertices",
                            scene.objects[object as usize]
                        ),
                    ));
                }
                let tris = match prim.mode() {
                    Mode::Triangles => indices
                        .chunks_exact(3)
                        .map(|t| [t[0], t[1], t[2]])
                        .collect::<Vec<_>>(),
                    Mode::TriangleStrip => (2..indices.len())
                        .map(|i| {
                            if i % 2 == 0 {
                                [indices[i - 2], indices[i - 1], indices[i]]
                            } else {
                                [indices[i - 1], indices[i - 2], indices[i]]
                            }
                        })
                        .collect(),
                    Mode::TriangleFan => (2..indices.len())
                        .map(|i| [indices[0], indices[i - 1], indices[i]])
                        .collect(),
                    other => {
                        warnings.push(format!(
                            "{}: skipped a primitive drawn as {other:?} (only triangles are baked)",
                            path.display()
                        ));
                        continue;
                    }
                };
                let material = match prim.material().index() {
                    Some(i) => material_ids[i],
                    None => scene.material_index(Material {
                        name: "gltf-default".into(),
                        albedo: [1.0; 3],
                        emission: [0.0; 3],
                    }),
                };
                for t in tris {
                    let t = if flip { [t[0], t[2], t[1]] } else { t };
                    scene.triangles.push(t.map(|i| base + i));
                    scene.triangle_material.push(material);
                    scene.triangle_object.push(object);
                }
            }
        }
        if let Some(light) = node.light() {
            let position = world.transform_point3(Vec3::ZERO);
            let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
            let kind = match light.kind() {
                gltf::khr_lights_punctual::Kind::Directional => LightKind::Directional,
                gltf::khr_lights_punctual::Kind::Point => LightKind::Point,
                gltf::khr_lights_punctual::Kind::Spot {
                    inner_cone_angle,
                    outer_cone_angle,
                } => LightKind::Spot {
                    inner_cone: inner_cone_angle,
                    outer_cone: outer_cone_angle,
                },
            };
            scene.lights.push(Light {
                name: light
                    .name()
                    .map(str::to_owned)
                    .unwrap_or_else(|| format!("light{}", light.index())),
                kind,
                position: position.to_array(),
                direction: direction.to_array(),
                color: light.color(),
                intensity: light.intensity(),
                range: light.range(),
            });
        }
        let children: Vec<_> = node.children().map(|c| (c, world)).collect();
        stack.extend(children.into_iter().rev());
    }
    if scene.triangles.is_empty() {
        return Err(Error::input(path, "the glTF scene has no triangles"));
    }
    Ok(scene)
}

/// Turn a `gltf` error into one naming the file and sorted by cause.
/// gltf-json 1.4's validation indexes the accessor a primitive's `POSITION` names before checking
/// that it exists, so a malformed file panics inside `gltf::import` (found by the bad-input
/// corpus). Check every accessor index a primitive names first; anything else malformed is left
/// to `gltf::import`'s own errors.
fn check_accessor_indices(path: &Path) -> Result<()> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, "cannot read scene", e))?;
    let Ok(gltf) = gltf::Gltf::from_slice_without_validation(&bytes) else {
        return Ok(());
    };
    let accessors = gltf.document.as_json().accessors.len();
    for (m, mesh) in gltf.document.as_json().meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let named = prim.attributes.values().chain(prim.indices.iter()).chain(
                prim.targets.iter().flatten().flat_map(|t| {
                    [&t.positions, &t.normals, &t.tangents]
                        .into_iter()
                        .flatten()
                }),
            );
            for a in named {
                if a.value() >= accessors {
                    return Err(Error::input(
                        path,
                        format!(
                            "mesh {m} primitive {p} names accessor {}, but the file has {accessors}",
                            a.value()
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

fn describe(path: &Path, e: gltf::Error) -> Error {
    match e {
        gltf::Error::Io(io) => Error::input(
            path,
            format!("a buffer or image the file refers to cannot be read: {io}"),
        ),
        gltf::Error::Binary(b) => Error::input(path, format!("broken GLB container: {b:?}")),
        gltf::Error::Deserialize(j) => Error::input(path, format!("invalid glTF JSON: {j}")),
        gltf::Error::Validation(v) => {
            let first: Vec<String> = v
                .iter()
                .take(3)
                .map(|(p, e)| format!("{}: {e}", p.as_str()))
                .collect();
            Error::input(path, format!("invalid glTF: {}", first.join("; ")))
        }
        gltf::Error::UnsupportedScheme => {
            Error::unsupported(path, "a URI uses an unsupported scheme")
        }
        other => Error::input(path, format!("cannot load glTF: {other}")),
    }
}

/// Mean linear RGB of a decoded glTF image (sRGB-encoded 8/16-bit, or float).
fn mean_linear_rgb(image: &gltf::image::Data) -> [f32; 3] {
    use gltf::image::Format::*;
    let (channels, bytes): (usize, usize) = match image.format {
        R8 => (1, 1),
        R8G8 => (2, 1),
        R8G8B8 => (3, 1),
        R8G8B8A8 => (4, 1),
        R16 => (1, 2),
        R16G16 => (2, 2),
        R16G16B16 => (3, 2),
        R16G16B16A16 => (4, 2),
        R32G32B32FLOAT => (3, 4),
        R32G32B32A32FLOAT => (4, 4),
    };
    let texel = channels * bytes;
    let n = image.pixels.len() / texel.max(1);
    if n == 0 {
        return [1.0; 3];
    }
    let mut sum = [0.0f64; 3];
    for px in image.pixels.chunks_exact(texel) {
        for (c, s) in sum.iter_mut().enumerate() {
            let ch = c.min(channels - 1);
            let v = match bytes {
                1 => srgb_to_linear(px[ch] as f32 / 255.0),
                2 => srgb_to_linear(
                    u16::from_le_bytes([px[2 * ch], px[2 * ch + 1]]) as f32 / 65535.0,
                ),
                _ => f32::from_le_bytes(px[4 * ch..4 * ch + 4].try_into().unwrap()),
            };
            *s += v as f64;
        }
    }
    let v = Vec4::new(sum[0] as f32, sum[1] as f32, sum[2] as f32, 0.0) / n as f32;
    [v.x, v.y, v.z]
}

/// The sRGB transfer function's inverse (IEC 61966-2-1).
pub(crate) fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}
