//! `relume-bake export DIR gltf`: the scene of a radiosity bake with its baked lighting for one
//! light setup, as a binary glTF 2.0 file that other tools open (Blender, three.js, any
//! glTF viewer), validated by the Khronos glTF-Validator in the tests.
//!
//! The lighting is what the player shows, evaluated on the CPU at every triangle corner:
//! direct exitance per patch (the lights' irradiance at the patch's sample points, shadow rays
//! through the BVH) → indirect light `B = S·E` from the bake's transport (the dense
//! `transport.npy` when present, else the encoded one) → per-corner interpolation → outgoing
//! radiance at the corner ([`crate::render::mesh_reference::shade_point`]: direct + indirect +
//! emission), at every vertex of a regular split of each triangle whose longest edge is over
//! `max_edge` (the indirect light interpolated from the triangle's corners, as the player does
//! per pixel; direct light and shadows evaluated at the vertex). The file holds, per object of
//! the scene, one indexed mesh (vertices are not shared between scene triangles, whose corners
//! carry their own light) with
//!
//! - `POSITION` (the scene's units), `NORMAL` (the face normal),
//! - `COLOR_0`: linear RGB radiance × `exposure`, clamped to [0, 1] (glTF's colour range), shown
//!   as is by an unlit material (`KHR_materials_unlit`, base colour 1),
//! - `_RADIANCE`: the unclamped linear radiance (W·sr⁻¹·m⁻² of the scene's units), for tools
//!   that tone-map themselves.
//!
//! Degenerate triangles are left out. Written atomically.

use crate::error::{Error, Result};
use crate::radiosity::patches::corners::PointTransfer;
use crate::render::direct::{gather_dense, patch_exitance};
use crate::render::lights::{sun_light, GpuLight};
use crate::render::mesh_reference::{shade_point, FrameSettings};
use crate::render::raycast::RaycastScene;
use crate::scene::{Light, Scene};
use crate::terrain::sun::Sun;
use glam::Vec3;
use serde::Serialize;
use serde_json::{json, Value};
use std::path::Path;

/// The light setup of an export.
#[derive(Clone, Debug, Default)]
pub struct LitExport {
    /// Punctual lights added to the scene's own.
    pub lights: Vec<Light>,
    /// A sun (the player's `--sun`).
    pub sun: Option<Sun>,
    /// Direct, indirect, shadows, emission, exposure and emission scale.
    pub settings: FrameSettings,
    /// Longest triangle edge in the file (scene units): longer triangles are split into a
    /// regular grid of sub-triangles so that direct light and shadows vary across them as in
    /// the player (which shades per pixel); None: 1/32 of the scene's diagonal.
    pub max_edge: Option<f32>,
}

/// Most sub-triangles along an edge when splitting by [`LitExport::max_edge`].
pub const MAX_SPLIT: usize = 64;

/// What an export wrote.
#[derive(Clone, Debug, Serialize)]
pub struct LitReport {
    pub out: String,
    pub bytes: u64,
    pub objects: usize,
    /// Triangles of the scene exported, and triangles and vertices in the file (after
    /// splitting by `max_edge`).
    pub scene_triangles: usize,
    pub triangles: usize,
    pub vertices: usize,
    pub degenerate_triangles_left_out: usize,
    pub lights: usize,
    pub transport: &'static str,
    /// Largest radiance of any vertex channel, and the fraction of vertex channels clamped in
    /// `COLOR_0`.
    pub max_radiance: f32,
    pub clamped_fraction: f64,
    /// Scene materials exported with their albedo texture (and alpha mask), and masks that
    /// could not travel ([`super::gltf_materials`]).
    pub textured_materials: usize,
    pub masks_left_out: usize,
}

/// A bake lit by a light setup: per-patch indirect exitance `b = S·E` (E: the direct exitance
/// of the setup's lights at the patches' sample points, plus emission).
pub struct LitPatches {
    pub scene: Scene,
    pub set: crate::radiosity::PatchSet,
    /// The scene's lights, the setup's, and its sun.
    pub lights: Vec<Light>,
    pub gpu_lights: Vec<GpuLight>,
    pub raycast: RaycastScene,
    pub b: Vec<[f32; 3]>,
    /// Which transport gave `b`: "dense", "encoded" or none.
    pub transport: &'static str,
}

/// Light the bake in `dir` with `setup`: read the scene, the patches and the transport, and
/// gather `b = S·E`.
pub fn lit_patches(dir: &Path, setup: &LitExport) -> Result<LitPatches> {
    let manifest = super::Manifest::read(dir)?;
    for need in [super::scene::FILE, super::patches::FILE] {
        if manifest.file(need).is_none() {
            return Err(Error::input(
                dir,
                format!("this bake has no `{need}`: glTF export and per-object light need a scene bake with `Voxelize` (see `relume-bake inspect`)"),
            ));
        }
    }
    let scene = super::scene::read(dir)?;
    let set = super::patches::read(dir)?;
    let mut lights: Vec<Light> = scene.lights.clone();
    lights.extend(setup.lights.iter().cloned());
    lights.extend(setup.sun.as_ref().map(sun_light));
    let gpu_lights: Vec<GpuLight> = lights
        .iter()
        .map(|l| GpuLight::from_light(l, 1.0, 0))
        .collect();
    let s = &setup.settings;
    let raycast = RaycastScene::for_visibility(&scene);
    let e = patch_exitance(&set, &gpu_lights, s, &raycast.visible(&gpu_lights));
    let n = set.patches.len();
    let (b, transport) = if manifest.file(super::transport::FILE).is_some() {
        let m = super::transport::read(dir)?;
        check_patches(dir, super::transport::FILE, m.n, n)?;
        (gather_dense(&m.data, m.channels, n, &e), "dense")
    } else if manifest.file(super::encoded::TRANSFER_FILE).is_some() {
        let enc = super::encoded::read(dir)?;
        check_patches(dir, super::encoded::TRANSFER_FILE, enc.dense.n, n)?;
        let ch = enc.dense.channels;
        let flat: Vec<f32> = (0..ch).flat_map(|c| e.iter().map(move |v| v[c])).collect();
        let g = crate::compress::gather(&enc, &flat);
        let b = (0..n)
            .map(|i| std::array::from_fn(|c| g[c.min(ch - 1) * n + i]))
            .collect();
        (b, "encoded")
    } else {
        (vec![[0.0; 3]; n], "none (direct light only)")
    };
    Ok(LitPatches {
        scene,
        set,
        lights,
        gpu_lights,
        raycast,
        b,
        transport,
    })
}

/// Export the bake in `dir` lit by `setup` to `out` (`.glb`).
pub fn export_lit_glb(dir: &Path, setup: &LitExport, out: &Path) -> Result<LitReport> {
    let LitPatches {
        scene,
        set,
        lights,
        gpu_lights,
        raycast: rs,
        b,
        transport,
    } = lit_patches(dir, setup)?;
    let s = &setup.settings;
    // Indirect light at every vertex of the split by the corners' own rule (PointTransfer):
    // blending a triangle's three corners would spread one corner's light over a whole wall
    // (the Cornell box's walls are one quad each). Shading data per corner as the player draws
    // it (emitters lifted off their wall).
    let vis = set.visibility(&scene);
    let transfer = PointTransfer::new(&scene, &set, &vis);
    let verts = rs.corner_data();
    let visible = rs.visible(&gpu_lights);
    let shade = |t: usize, w: [f32; 3]| -> Shaded {
        let at = |k: usize, f: usize| Vec3::from_slice(&verts[12 * (3 * t + k) + f..][..3]);
        let blend = |f: usize| at(0, f) * w[0] + at(1, f) * w[1] + at(2, f) * w[2];
        let c = scene.corners(t);
        let p = c[0] * w[0] + c[1] * w[1] + c[2] * w[2];
        let ind: Vec3 = transfer
            .on_triangle(&scene, t)
            .weights(p)
            .iter()
            .map(|&(j, wj)| Vec3::from(b[j as usize]) * wj)
            .sum();
        let radiance = shade_point(
            s,
            &gpu_lights,
            blend(0),
            at(0, 3),
            at(0, 6),
            at(0, 9),
            ind,
            &visible,
        );
        // Textured: the light per unit albedo (the patches reflect the material's mean albedo,
        // the vertex albedo), which the viewer multiplies by factor × texture.
        let colour = if scene.materials[scene.triangle_material[t] as usize].is_textured() {
            let mean = at(0, 6).max(Vec3::splat(1e-6));
            shade_point(
                s,
                &gpu_lights,
                blend(0),
                at(0, 3),
                Vec3::ONE,
                at(0, 9) / mean,
                ind / mean,
                &visible,
            )
        } else {
            radiance
        };
        (radiance.to_array(), colour.to_array())
    };
    let (lo, hi) = scene.bounds();
    let max_edge = setup.max_edge.unwrap_or((hi - lo).length() / 32.0);
    let (glb, mut report) = build_glb(&scene, &shade, Some(max_edge), s.exposure)?;
    super::images::write_atomic(out, |tmp| {
        std::fs::write(tmp, &glb).map_err(|e| Error::io(tmp, "cannot write", e))
    })?;
    report.out = out.display().to_string();
    report.bytes = glb.len() as u64;
    report.lights = lights.len();
    report.transport = transport;
    Ok(report)
}

/// One scene triangle split m × m: its grid's positions, shading and texture coordinates
/// (empty when untextured), and m.
type SplitTriangle = (Vec<[f32; 3]>, Vec<Shaded>, Vec<[f32; 2]>, usize);

/// A transport of `got` patches in a bake of `want`: files of different bakes.
fn check_patches(dir: &Path, file: &str, got: usize, want: usize) -> Result<()> {
    if got == want {
        return Ok(());
    }
    Err(Error::input(
        dir.join(file),
        format!(
            "is the transport of {got} patches, but {} holds {want}: files of different bakes",
            super::patches::FILE
        ),
    ))
}

/// What [`build_glb`] writes at one vertex: the outgoing radiance (`_RADIANCE`) and the vertex
/// colour before exposure (the radiance on untextured surfaces, the light per unit albedo on
/// textured ones, which the viewer multiplies by factor × texture).
pub type Shaded = ([f32; 3], [f32; 3]);

/// The GLB bytes of `scene` with `shade(t, w)` at barycentric weights `w` of triangle t;
/// triangles longer than `max_edge` are split into m² sub-triangles (m ≤ [`MAX_SPLIT`]). One
/// mesh per object, one primitive per material look in it ([`super::gltf_materials`]).
pub fn build_glb(
    scene: &Scene,
    shade: &(dyn Fn(usize, [f32; 3]) -> Shaded + Sync),
    max_edge: Option<f32>,
    exposure: f32,
) -> Result<(Vec<u8>, LitReport)> {
    use super::gltf_materials::{materials, Look};
    use rayon::prelude::*;
    let degenerate: std::collections::BTreeSet<usize> = scene.degenerate_triangles().collect();
    let mut bin: Vec<u8> = Vec::new();
    let (mut views, mut accessors, mut meshes, mut nodes) = (vec![], vec![], vec![], vec![]);
    let mut push_view = |bin: &mut Vec<u8>, bytes: Vec<u8>, target: Option<u32>| -> usize {
        // Accessor data stays 4-byte aligned after images of any length.
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let offset = bin.len();
        let len = bytes.len();
        bin.extend(bytes);
        let mut view = json!({"buffer": 0, "byteOffset": offset, "byteLength": len});
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        views.push(view);
        views.len() - 1
    };
    let looks = materials(scene, &mut |png| push_view(&mut bin, png, None))?;
    let (mut clamped, mut channels, mut max_radiance) = (0usize, 0usize, 0.0f32);
    let (mut triangles, mut vertices) = (0usize, 0usize);
    let uvs = |t: usize, w: [f32; 3], r: &crate::scene::texture::TextureRef| -> [f32; 2] {
        if scene.uvs.is_empty() {
            return r.apply([0.0, 0.0]);
        }
        let c = scene.triangles[t].map(|v| scene.uvs[v as usize]);
        r.apply([0, 1].map(|k| c[0][k] * w[0] + c[1][k] * w[1] + c[2][k] * w[2]))
    };
    for (o, name) in scene.objects.iter().enumerate() {
        // The object's triangles by look: the plain material first, then each textured one.
        let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
        for t in 0..scene.triangles.len() {
            if scene.triangle_object[t] as usize != o || degenerate.contains(&t) {
                continue;
            }
            match &looks.looks[scene.triangle_material[t] as usize] {
                Look::Hidden => {}
                Look::Plain => groups.entry(0).or_default().push(t),
                Look::Textured { material, .. } => groups.entry(*material).or_default().push(t),
            }
        }
        let mut primitives = vec![];
        for (material, tris) in groups {
            let texture = tris.first().and_then(|&t| {
                match &looks.looks[scene.triangle_material[t] as usize] {
                    Look::Textured { uv, .. } => Some(uv.clone()),
                    _ => None,
                }
            });
            // Per triangle: its grid vertices (barycentric (1 − (i + j)/m, i/m, j/m)) shaded in
            // parallel, then indices into the primitive's vertex list.
            let parts: Vec<SplitTriangle> = tris
                .par_iter()
                .map(|&t| {
                    let c = scene.corners(t);
                    let longest = (0..3)
                        .map(|k| (c[(k + 1) % 3] - c[k]).length())
                        .fold(0.0, f32::max);
                    let m =
                        max_edge.map_or(1, |e| ((longest / e).ceil() as usize).clamp(1, MAX_SPLIT));
                    let (mut pos, mut lit, mut uv) = (vec![], vec![], vec![]);
                    for i in 0..=m {
                        for j in 0..=m - i {
                            let (u, v) = (i as f32 / m as f32, j as f32 / m as f32);
                            let w = [1.0 - u - v, u, v];
                            pos.push((c[0] * w[0] + c[1] * w[1] + c[2] * w[2]).to_array());
                            lit.push(shade(t, w));
                            if let Some(r) = &texture {
                                uv.push(uvs(t, w, r));
                            }
                        }
                    }
                    (pos, lit, uv, m)
                })
                .collect();
            let (mut pos, mut nor, mut col, mut rad, mut tex, mut idx) =
                (vec![], vec![], vec![], vec![], vec![], vec![]);
            for (&t, (p, lit, uv, m)) in tris.iter().zip(&parts) {
                let c = scene.corners(t);
                let nrm = (c[1] - c[0]).cross(c[2] - c[0]).normalize().to_array();
                let base = (pos.len() / 3) as u32;
                // Vertex (i, j) is at offset row(i) + j, row(i) = Σ_{a<i} (m + 1 − a).
                let row = |i: usize| (i * (2 * m + 3) - i * i) / 2;
                for i in 0..*m {
                    for j in 0..m - i {
                        let (a, b, d) = (row(i) + j, row(i + 1) + j, row(i) + j + 1);
                        idx.extend([a, b, d].map(|v| base + v as u32));
                        if j + 1 < m - i {
                            let e = row(i + 1) + j + 1;
                            idx.extend([b, e, d].map(|v| base + v as u32));
                        }
                    }
                }
                triangles += m * m;
                for (pp, (rr, cc)) in p.iter().zip(lit) {
                    pos.extend_from_slice(pp);
                    nor.extend_from_slice(&nrm);
                    for (&v, &k) in rr.iter().zip(cc) {
                        if !v.is_finite() || !k.is_finite() {
                            return Err(Error::Internal(format!("radiance {v} at triangle {t}")));
                        }
                        max_radiance = max_radiance.max(v);
                        let x = k * exposure;
                        clamped += (x > 1.0) as usize;
                        channels += 1;
                        col.push(x.clamp(0.0, 1.0));
                    }
                    rad.extend_from_slice(rr);
                }
                tex.extend(uv.iter().flatten());
            }
            let count = pos.len() / 3;
            vertices += count;
            let (lo, hi) = pos.chunks_exact(3).fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), p| {
                    let p = Vec3::from_slice(p);
                    (lo.min(p), hi.max(p))
                },
            );
            let floats = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
            let mut attr = serde_json::Map::new();
            let mut streams = vec![
                ("POSITION", &pos, "VEC3", Some((lo, hi))),
                ("NORMAL", &nor, "VEC3", None),
                ("COLOR_0", &col, "VEC3", None),
                ("_RADIANCE", &rad, "VEC3", None),
            ];
            if texture.is_some() {
                streams.push(("TEXCOORD_0", &tex, "VEC2", None));
            }
            for (name, data, kind, bounds) in streams {
                let view = push_view(&mut bin, floats(data), Some(34962));
                let mut acc = json!({"bufferView": view, "componentType": 5126, "count": count, "type": kind});
                if let Some((lo, hi)) = bounds {
                    acc["min"] = json!(lo.to_array());
                    acc["max"] = json!(hi.to_array());
                }
                accessors.push(acc);
                attr.insert(name.into(), json!(accessors.len() - 1));
            }
            let view = push_view(
                &mut bin,
                idx.iter().flat_map(|i| i.to_le_bytes()).collect(),
                Some(34963),
            );
            accessors.push(json!({"bufferView": view, "componentType": 5125, "count": idx.len(), "type": "SCALAR"}));
            let indices = accessors.len() - 1;
            primitives.push(
                json!({"attributes": attr, "indices": indices, "material": material, "mode": 4}),
            );
        }
        if primitives.is_empty() {
            continue;
        }
        meshes.push(json!({"name": name, "primitives": primitives}));
        nodes.push(json!({"name": name, "mesh": meshes.len() - 1}));
    }
    if nodes.is_empty() {
        return Err(Error::input(
            super::scene::FILE,
            "the scene has no triangle that is not degenerate",
        ));
    }
    let node_ids: Vec<usize> = (0..nodes.len()).collect();
    let textured_materials = looks.materials.len() - 1;
    let doc: Value = json!({
        "asset": {"version": "2.0", "generator": format!("relume-bake {}", env!("CARGO_PKG_VERSION"))},
        "extensionsUsed": ["KHR_materials_unlit"],
        "scene": 0,
        "scenes": [{"nodes": node_ids, "extras": {"relume": {
            "lighting": "baked radiosity: direct + indirect + emission per vertex (linear)",
            "COLOR_0": "radiance x exposure, clamped to [0, 1]; on textured materials the light per unit albedo (radiance / albedo) x exposure, which the base colour (factor x texture) multiplies",
            "_RADIANCE": "linear outgoing radiance, unclamped",
            "exposure": exposure,
        }}}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": looks.materials,
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
    });
    let mut doc = doc;
    for (key, list) in [
        ("images", looks.images),
        ("textures", looks.textures),
        ("samplers", looks.samplers),
    ] {
        if !list.is_empty() {
            doc[key] = Value::Array(list);
        }
    }
    let json = serde_json::to_vec(&doc)
        .map_err(|e| Error::Internal(format!("cannot encode glTF JSON: {e}")))?;
    let glb = ::gltf::binary::Glb {
        header: ::gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0, // to_vec computes the real length
        },
        json: std::borrow::Cow::Owned(json),
        bin: Some(std::borrow::Cow::Owned(bin)),
    }
    .to_vec()
    .map_err(|e| Error::Internal(format!("cannot write GLB: {e}")))?;
    let report = LitReport {
        out: String::new(),
        bytes: 0,
        objects: meshes.len(),
        scene_triangles: scene.triangles.len() - degenerate.len(),
        triangles,
        vertices,
        degenerate_triangles_left_out: degenerate.len(),
        lights: 0,
        transport: "",
        max_radiance,
        clamped_fraction: clamped as f64 / channels.max(1) as f64,
        textured_materials,
        masks_left_out: looks.masks_left_out,
    };
    Ok((glb, report))
}
