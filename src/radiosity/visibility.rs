//! Ray visibility through an obvhs compressed-wide BVH over the scene's triangles, in grid
//! coordinates (f32). Two queries: the closest hit (hemisphere shooting) and occlusion of a
//! segment (pairwise form factors, patch clustering, the transfer's leak test).
//!
//! Occlusion uses `CwBvh::ray_traverse_miss`, which stops at the first hit below `tmax`;
//! `ray_traverse_anyhit` is *not* an occlusion test (it visits every hit) — see BUILD-NOTES.

use super::geometry::Frame;
use crate::scene::Scene;
use glam::{DVec3, Vec3A};
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use std::time::Duration;

/// The scene's non-degenerate triangles in a BVH.
pub struct Visibility {
    bvh: CwBvh,
    tris: Vec<Triangle>,
    /// Scene triangle index of each BVH triangle.
    ids: Vec<u32>,
    /// Unit geometric normal (from the counter-clockwise winding) of each BVH triangle.
    normals: Vec<Vec3A>,
    /// Smallest ray parameter accepted, in grid units (above f32 self-intersection noise).
    pub epsilon: f32,
}

/// The closest surface a ray hits.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Scene triangle index.
    pub triangle: u32,
    pub t: f32,
    /// True when the ray hit the triangle's front (counter-clockwise) side.
    pub front: bool,
}

impl Visibility {
    /// Build over the triangles of `scene` listed in `triangles` (scene indices), mapped into
    /// grid coordinates by `frame`. `extent` is the grid's largest dimension, which sets the
    /// ray epsilon.
    pub fn new(scene: &Scene, triangles: &[u32], frame: &Frame, extent: f64) -> Self {
        let tris: Vec<Triangle> = triangles
            .iter()
            .map(|&t| {
                let [a, b, c] = scene.triangles[t as usize]
                    .map(|v| frame.to_grid(scene.positions[v as usize]).as_vec3().into());
                Triangle {
                    v0: a,
                    v1: b,
                    v2: c,
                }
            })
            .collect();
        let normals = tris.iter().map(|t| t.compute_normal()).collect();
        let bvh = build_cwbvh_from_tris(
            &tris,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        Visibility {
            bvh,
            tris,
            ids: triangles.to_vec(),
            normals,
            epsilon: ray_epsilon(extent),
        }
    }

    /// Number of triangles in the BVH.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// The closest hit along `dir` (unit) from `origin`, ignoring hits closer than the epsilon.
    pub fn closest_hit(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        let d = Vec3A::from(dir.as_vec3());
        let ray = Ray::new(
            Vec3A::from(origin.as_vec3()),
            d,
            self.epsilon,
            f32::INFINITY,
        );
        let mut hit = RayHit::none();
        let found = self.bvh.ray_traverse(ray, &mut hit, |r, id| {
            self.tris[self.bvh.primitive_indices[id] as usize].intersect(r)
        });
        if !found {
            return None;
        }
        let k = self.bvh.primitive_indices[hit.primitive_id as usize] as usize;
        Some(Hit {
            triangle: self.ids[k],
            t: hit.t,
            front: self.normals[k].dot(d) < 0.0,
        })
    }

    /// True when a surface lies strictly between `from` and `to` (ignoring an epsilon at both
    /// ends, so surfaces the end points lie on do not count).
    pub fn occluded(&self, from: DVec3, to: DVec3) -> bool {
        let delta = to - from;
        let len = delta.length();
        let eps = self.epsilon as f64;
        if len <= 2.0 * eps {
            return false;
        }
        let dir = delta / len;
        let ray = Ray::new(
            Vec3A::from(from.as_vec3()),
            Vec3A::from(dir.as_vec3()),
            self.epsilon,
            (len - eps) as f32,
        );
        !self.bvh.ray_traverse_miss(ray, |r, id| {
            self.tris[self.bvh.primitive_indices[id] as usize].intersect(r)
        })
    }
}

/// The ray epsilon for a grid whose largest coordinate is `extent`: a few hundred f32 ulps of the
/// coordinates, never below 1e-5 of a voxel.
pub fn ray_epsilon(extent: f64) -> f32 {
    (256.0 * f32::EPSILON as f64 * extent.max(1.0)).max(1e-5) as f32
}
