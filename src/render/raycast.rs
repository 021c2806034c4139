//! The CPU reference image of a mesh frame: one primary ray per pixel centre through the same
//! camera, the same per-corner vertex data and indirect light as the GPU, `shade_point` and the
//! tone map; punctual-light visibility by shadow rays through the BVH (the GPU uses shadow maps,
//! so the two images differ only near shadow edges). Albedo textures are read through
//! [`SceneMaps`] at the level of detail of the pixel's footprint (ray differentials to the
//! neighbouring pixels' rays); alpha masks by the tracer's nearest-texel rule (the GPU filters
//! them, so mask edges may differ by a pixel).

use super::camera::Camera;
use super::lights::{GpuLight, KIND_DIRECTIONAL};
use super::material_maps::{level_of_detail, SceneMaps};
use super::mesh_reference::{corner_uvs, corner_vertices, display, shade_point, FrameSettings};
use super::tonemap::to_u8;
use crate::radiosity::geometry::Frame;
use crate::raytrace::visibility::Visibility;
use crate::scene::{Material, Scene};
use glam::{DVec3, Vec2, Vec3};
use rayon::prelude::*;

/// A scene prepared for reference ray casting.
pub struct RaycastScene {
    verts: Vec<f32>,
    vis: Visibility,
    extent: f32,
    /// Per-corner texture coordinates, the material of each triangle, and the maps.
    uvs: Vec<f32>,
    triangle_material: Vec<u32>,
    /// None when built [`RaycastScene::for_visibility`]: frames then show mean albedos.
    maps: Option<SceneMaps>,
}

impl RaycastScene {
    /// Build the BVH over the same (lifted) corner positions the GPU draws; alpha-masked
    /// materials keep their masks, so shadow rays pass through cut-out texels; and the texture
    /// mip chains [`RaycastScene::render`] reads.
    pub fn new(scene: &Scene) -> Self {
        RaycastScene {
            maps: Some(SceneMaps::new(scene, u32::MAX)),
            ..Self::for_visibility(scene)
        }
    }

    /// [`RaycastScene::new`] without the texture mip chains, for callers that only ask
    /// [`RaycastScene::visible`] (lit exports, per-object direct light): [`RaycastScene::render`]
    /// then shows each material's mean albedo.
    pub fn for_visibility(scene: &Scene) -> Self {
        let verts = corner_vertices(scene);
        let corners = verts.len() / 12;
        let masked = scene.materials.iter().any(|m| m.alpha.is_some());
        let flat = Scene {
            positions: (0..corners)
                .map(|k| [verts[12 * k], verts[12 * k + 1], verts[12 * k + 2]])
                .collect(),
            triangles: (0..corners as u32 / 3)
                .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
                .collect(),
            triangle_material: if masked {
                scene.triangle_material.clone()
            } else {
                vec![0; corners / 3]
            },
            triangle_object: vec![0; corners / 3],
            objects: vec!["all".into()],
            materials: if masked {
                scene.materials.clone()
            } else {
                vec![Material::default_grey()]
            },
            uvs: if masked && !scene.uvs.is_empty() {
                scene
                    .triangles
                    .iter()
                    .flat_map(|t| t.map(|v| scene.uvs[v as usize]))
                    .collect()
            } else {
                Vec::new()
            },
            textures: if masked {
                scene.textures.clone()
            } else {
                Vec::new()
            },
            ..Default::default()
        };
        let live = flat.live_triangles();
        let (lo, hi) = flat.bounds();
        let extent = lo.abs().max(hi.abs()).max_element().max(1e-6);
        let vis = Visibility::new(
            &flat,
            &live,
            &Frame {
                origin: DVec3::ZERO,
                scale: 1.0,
            },
            extent as f64,
        );
        RaycastScene {
            verts,
            vis,
            extent,
            uvs: corner_uvs(scene),
            triangle_material: scene.triangle_material.clone(),
            maps: None,
        }
    }

    /// The textured albedo seen through pixel (`x`, `y`) where its ray hits triangle `t` at `p`
    /// (`None` for an untextured material): the map read at the level of detail of the pixel's
    /// footprint, from where the neighbouring pixels' rays meet the triangle's plane.
    #[allow(clippy::too_many_arguments)]
    fn textured_albedo(
        &self,
        camera: &Camera,
        (x, y, width, height): (u32, u32, u32, u32),
        t: usize,
        p: Vec3,
        corners: [Vec3; 3],
    ) -> Option<Vec3> {
        let m = self.triangle_material[t] as usize;
        let maps = self.maps.as_ref()?;
        let (tw, th) = maps.base_size(m)?;
        let [a, b, c] = corners;
        let uv_at = |q: Vec3| {
            let w = barycentric(q, a, b, c);
            (0..3)
                .map(|k| w[k] * Vec2::from_slice(&self.uvs[2 * (3 * t + k)..][..2]))
                .sum::<Vec2>()
        };
        let n = (b - a).cross(c - a);
        let on_plane = |px: u32, py: u32| {
            let (o, d) = camera.ray(px, py, width, height);
            let den = n.dot(d);
            (den.abs() > 0.0).then(|| o + d * (n.dot(a - o) / den))
        };
        let uv = uv_at(p);
        let look = maps.materials[m]
            .albedo
            .as_ref()
            .map(|(_, l)| l)
            .or(maps.materials[m].mask.as_ref().map(|(_, l, _)| l))?;
        let image = |q: Vec3| look.apply(uv_at(q)) - look.apply(uv);
        let lod = match (on_plane(x + 1, y), on_plane(x, y + 1)) {
            (Some(qx), Some(qy)) => level_of_detail(image(qx), image(qy), tw, th),
            _ => 0.0,
        };
        maps.albedo_at(m, uv, lod)
    }

    /// Per-corner vertex data the scene was built from ([`corner_vertices`]: 12 floats per
    /// corner, emitters lifted).
    pub fn corner_data(&self) -> &[f32] {
        &self.verts
    }

    /// Whether light `l` of `lights` reaches point `p` (normal `n`, unit vector `to_light`,
    /// distance `dist`): a shadow ray through the BVH from `p` lifted by the BVH's epsilon along
    /// `n` (the closure [`shade_point`] and [`super::direct::patch_exitance`] take).
    pub fn visible<'a>(
        &'a self,
        lights: &'a [GpuLight],
    ) -> impl Fn(usize, Vec3, Vec3, Vec3, f32) -> bool + Sync + 'a {
        let far = 4.0 * self.extent;
        let eps = self.vis.epsilon;
        move |l: usize, p: Vec3, n: Vec3, to_light: Vec3, dist: f32| {
            let end = if lights[l].kind() == KIND_DIRECTIONAL {
                p + to_light * far
            } else {
                p + to_light * dist
            };
            !self.vis.occluded((p + n * eps).as_dvec3(), end.as_dvec3())
        }
    }

    /// Render `width`×`height` RGBA8 with per-corner indirect exitance `indirect` (3 floats per
    /// corner, or empty for none).
    pub fn render(
        &self,
        camera: &Camera,
        lights: &[GpuLight],
        s: &FrameSettings,
        indirect: &[f32],
        width: u32,
        height: u32,
    ) -> image::RgbaImage {
        let bg = s.background.map(to_u8);
        let visible = self.visible(lights);
        let rows: Vec<Vec<u8>> = (0..height)
            .into_par_iter()
            .map(|y| {
                let mut row = Vec::with_capacity(width as usize * 4);
                for x in 0..width {
                    let (o, d) = camera.ray(x, y, width, height);
                    let px = match self.vis.closest_hit(o.as_dvec3(), d.as_dvec3()) {
                        None => [bg[0], bg[1], bg[2], 255],
                        Some(hit) => {
                            let t = hit.triangle as usize;
                            let v = |k: usize, f: usize| {
                                Vec3::from_slice(&self.verts[12 * (3 * t + k) + f..][..3])
                            };
                            let p = o + d * hit.t;
                            let (a, b, c) = (v(0, 0), v(1, 0), v(2, 0));
                            let w = barycentric(p, a, b, c);
                            let mut n = v(0, 3);
                            if n.dot(d) > 0.0 {
                                n = -n;
                            }
                            let ind = if indirect.is_empty() {
                                Vec3::ZERO
                            } else {
                                (0..3)
                                    .map(|k| {
                                        w[k] * Vec3::from_slice(&indirect[3 * (3 * t + k)..][..3])
                                    })
                                    .sum()
                            };
                            let albedo = if s.textures {
                                self.textured_albedo(camera, (x, y, width, height), t, p, [a, b, c])
                            } else {
                                None
                            };
                            // The patches reflect the material's mean albedo (the vertex
                            // albedo); a texel's departure from it modulates indirect light.
                            let (albedo, ind) = match albedo {
                                Some(a) => (a, ind * a / v(0, 6).max(Vec3::splat(1e-6))),
                                None => (v(0, 6), ind),
                            };
                            let rad = shade_point(s, lights, p, n, albedo, v(0, 9), ind, &visible);
                            let c = display(s, rad);
                            [to_u8(c[0]), to_u8(c[1]), to_u8(c[2]), 255]
                        }
                    };
                    row.extend_from_slice(&px);
                }
                row
            })
            .collect();
        image::RgbaImage::from_raw(width, height, rows.concat()).expect("size matches")
    }
}

/// Barycentric weights of `p` in triangle (a, b, c).
fn barycentric(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> [f32; 3] {
    let (v0, v1, v2) = (b - a, c - a, p - a);
    let (d00, d01, d11, d20, d21) = (v0.dot(v0), v0.dot(v1), v1.dot(v1), v2.dot(v0), v2.dot(v1));
    let den = d00 * d11 - d01 * d01;
    if den.abs() < f32::MIN_POSITIVE {
        return [1.0, 0.0, 0.0];
    }
    let v = (d11 * d20 - d01 * d21) / den;
    let w = (d00 * d21 - d01 * d20) / den;
    [1.0 - v - w, v, w]
}
