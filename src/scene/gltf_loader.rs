//! glTF 2.0 (`.gltf` with external or embedded buffers, `.glb`) through the `gltf` crate.
//!
//! Node transforms are applied (negative-determinant transforms flip the winding back);
//! `baseColorFactor` → albedo factor, `baseColorTexture` (its `texCoord` set, sampler wrap modes
//! and `KHR_texture_transform`) → albedo texture; `alphaMode` `MASK` (at `alphaCutoff`) and
//! `BLEND` (at 0.5) → alpha mask from the factor's and the texture's alpha;
//! `emissiveFactor` × `KHR_materials_emissive_strength` → emitted radiance;
//! `KHR_lights_punctual` directional, point and spot lights → [`Light`]s.

use super::texture::{AlphaMask, Channel, Texture, TextureRef, Wrap};
use super::{Light, LightKind, LoadWarnings, Material, Scene};
use crate::error::{Error, Result};
use glam::{Mat4, Vec3};
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
    // The texture coordinate set each material's base colour reads, per material.
    let mut material_ids = Vec::new();
    let mut uv_sets = Vec::new();
    let mut image_ids: Vec<Option<u32>> = vec![None; images.len()];
    for m in doc.materials() {
        let pbr = m.pbr_metallic_roughness();
        let factor = pbr.base_color_factor();
        let mut albedo = [0.0f32; 3];
        albedo.copy_from_slice(&factor[..3]);
        let texture = match pbr.base_color_texture() {
            Some(info) => {
                let source = info.texture().source().index();
                let id = match image_ids[source] {
                    Some(id) => id,
                    None => {
                        let name = format!("{}#image {source}", path.display());
                        scene
                            .textures
                            .push(texture_of(path, name, &images[source])?);
                        let id = (scene.textures.len() - 1) as u32;
                        image_ids[source] = Some(id);
                        id
                    }
                };
                let (reference, set) = reference(id, &info);
                uv_sets.push(Some(set));
                Some(reference)
            }
            None => {
                uv_sets.push(None);
                None
            }
        };
        let alpha = match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => None,
            mode => Some(AlphaMask {
                factor: factor[3],
                texture: texture.clone().map(|t| (t, Channel::Alpha)),
                cutoff: match mode {
                    gltf::material::AlphaMode::Mask => m.alpha_cutoff().unwrap_or(0.5),
                    _ => 0.5,
                },
            }),
        };
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
            albedo_texture: texture,
            alpha,
        }));
    }
    let mut uvs: Vec<[f32; 2]> = Vec::new();

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
                let mut material = match prim.material().index() {
                    Some(i) => material_ids[i],
                    None => {
                        scene.material_index(Material::plain("gltf-default", [1.0; 3], [0.0; 3]))
                    }
                };
                let set = prim.material().index().and_then(|i| uv_sets[i]);
                let coords = set
                    .and_then(|s| reader.read_tex_coords(s))
                    .map(|t| t.into_f32());
                match coords {
                    Some(t) => {
                        uvs.resize(base as usize, [0.0; 2]);
                        uvs.extend(t.take(count as usize));
                        uvs.resize((base + count) as usize, [0.0; 2]);
                    }
                    None if set.is_some() => {
                        let mut plain = scene.materials[material as usize].clone();
                        warnings.push(format!(
                            "{}: mesh `{}` uses textured material `{}` but has no TEXCOORD_{}; using its colour factor alone",
                            path.display(),
                            scene.objects[object as usize],
                            plain.name,
                            set.unwrap_or(0)
                        ));
                        plain.albedo_texture = None;
                        plain.alpha = plain.alpha.filter(|a| a.texture.is_none());
                        material = scene.material_index(plain);
                    }
                    None => {}
                }
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
        if let Some(camera) = node.camera() {
            let name = node
                .name()
                .or(camera.name())
                .map_or_else(|| format!("camera{}", camera.index()), str::to_owned);
            match camera.projection() {
                gltf::camera::Projection::Perspective(p) => {
                    let eye = world.transform_point3(Vec3::ZERO);
                    let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
                    let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
                    if forward != Vec3::ZERO && up != Vec3::ZERO && p.yfov() > 0.0 {
                        scene.viewpoints.push(crate::scene::Viewpoint {
                            name,
                            eye: eye.to_array(),
                            target: (eye + forward).to_array(),
                            up: up.to_array(),
                            fov_y_deg: p.yfov().to_degrees(),
                        });
                    } else {
                        warnings.push(format!("camera `{name}` has a degenerate transform or field of view; ignored"));
                    }
                }
                gltf::camera::Projection::Orthographic(_) => warnings.push(format!(
                    "camera `{name}` is orthographic; the player's cameras are perspective, so it is ignored"
                )),
            }
        }
        let children: Vec<_> = node.children().map(|c| (c, world)).collect();
        stack.extend(children.into_iter().rev());
    }
    if scene.triangles.is_empty() {
        return Err(Error::input(path, "the glTF scene has no triangles"));
    }
    if !uvs.is_empty() {
        uvs.resize(scene.positions.len(), [0.0; 2]);
        scene.uvs = uvs;
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

/// The reference a material's base-colour texture makes (sampler wrap modes,
/// `KHR_texture_transform` as `T·R·S`), and the texture coordinate set it reads.
fn reference(id: u32, info: &gltf::texture::Info) -> (TextureRef, u32) {
    use gltf::texture::WrappingMode as W;
    let wrap = |w: W| match w {
        W::Repeat => Wrap::Repeat,
        W::ClampToEdge => Wrap::ClampToEdge,
        W::MirroredRepeat => Wrap::MirroredRepeat,
    };
    let sampler = info.texture().sampler();
    let mut r = TextureRef::new(id);
    r.wrap = [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())];
    let mut set = info.tex_coord();
    if let Some(t) = info.texture_transform() {
        let ([ox, oy], a, [sx, sy]) = (t.offset(), t.rotation(), t.scale());
        let (sin, cos) = a.sin_cos();
        r.transform = [[cos * sx, sin * sy, ox], [-sin * sx, cos * sy, oy]];
        set = t.tex_coord().unwrap_or(set);
    }
    (r, set)
}

/// A decoded glTF image as a texture: 8-bit kept, 16-bit rounded to 8, float sRGB-encoded;
/// grey (R) and grey-alpha (RG) images become RGB(A) with R = G = B.
fn texture_of(path: &Path, name: String, image: &gltf::image::Data) -> Result<Texture> {
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
    let n = image.width as usize * image.height as usize;
    if image.pixels.len() != n * texel {
        return Err(Error::input(
            path,
            format!(
                "image `{name}` holds {} bytes for {n} texels",
                image.pixels.len()
            ),
        ));
    }
    let value = |px: &[u8], ch: usize, colour: bool| -> u8 {
        match bytes {
            1 => px[ch],
            2 => (u16::from_le_bytes([px[2 * ch], px[2 * ch + 1]]) as f32 / 257.0).round() as u8,
            _ => {
                let v = f32::from_le_bytes(px[4 * ch..4 * ch + 4].try_into().unwrap());
                let v = if colour {
                    super::texture::linear_to_srgb(v.max(0.0))
                } else {
                    v
                };
                (v.clamp(0.0, 1.0) * 255.0).round() as u8
            }
        }
    };
    let mut texels = Vec::with_capacity(4 * n);
    for px in image.pixels.chunks_exact(texel) {
        let rgb = |c: usize| value(px, if channels < 3 { 0 } else { c }, true);
        let alpha = match channels {
            2 => value(px, 1, false),
            4 => value(px, 3, false),
            _ => 255,
        };
        texels.extend([rgb(0), rgb(1), rgb(2), alpha]);
    }
    Texture::from_rgba8(name, image.width, image.height, texels)
}
