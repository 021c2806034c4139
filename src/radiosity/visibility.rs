//! Ray visibility through an obvhs compressed-wide BVH over the scene's triangles, in grid
//! coordinates (f32). Two queries: the closest hit (hemisphere shooting) and occlusion of a
//! segment (pairwise form factors, patch clustering, the transfer's leak test).
//!
//! Triangles are tested with a watertight intersection (no rays lost through shared edges).
//! Rays start slightly behind their origin to dodge obvhs's absolute 1e-4 near-hit cut-off.
//! Occlusion uses `CwBvh::ray_traverse_miss`, which stops at the first hit below `tmax`;
//! `ray_traverse_anyhit` is *not* an occlusion test (it visits every hit) — see docs/dependencies.md.

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

/// obvhs's CWBVH node test clamps the entry distance to an absolute 1e-4 (`cwbvh::node::EPSILON`),
/// so a hit closer than that to the ray's start is lost — a ray leaving a floor point 1e-5 from a
/// wall would escape through the wall. Rays therefore start `BACKOFF` behind their origin and only
/// hits at or beyond `BACKOFF` count.
pub const BACKOFF: f32 = 2.5e-4;

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
            BvhBuildParams::slow_build(),
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

    /// Over the live triangles of `scene` in the grid frame of `set`, its voxelization.
    pub fn for_patches(scene: &Scene, set: &super::PatchSet) -> Self {
        let extent = set.dims.iter().copied().max().unwrap_or(1) as f64;
        Visibility::new(scene, &scene.live_triangles(), &set.frame(), extent)
    }

    /// The BVH's triangles as (scene triangle index, vertices in grid coordinates, f32): what
    /// an independent tracer needs to trace the same rays (tests/visibility_embree.rs).
    pub fn triangles(&self) -> impl Iterator<Item = (u32, [[f32; 3]; 3])> + '_ {
        self.ids
            .iter()
            .zip(&self.tris)
            .map(|(&id, t)| (id, [t.v0, t.v1, t.v2].map(|v| [v.x, v.y, v.z])))
    }

    /// Number of triangles in the BVH.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// The closest hit along `dir` (unit) from `origin`. Callers start rays slightly off the
    /// surface (lifted by [`Visibility::epsilon`] along its normal), so every hit with t ≥ 0 counts.
    pub fn closest_hit(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        let start = origin - dir * BACKOFF as f64;
        let wt = Watertight::new(start, dir);
        let ray = Ray::new(
            Vec3A::from(start.as_vec3()),
            Vec3A::from(dir.as_vec3()),
            0.0,
            f32::INFINITY,
        );
        let mut hit = RayHit::none();
        let found = self.bvh.ray_traverse(ray, &mut hit, |r, id| {
            self.hit_distance(
                &wt,
                self.bvh.primitive_indices[id] as usize,
                dir,
                BACKOFF,
                r.tmax,
            )
        });
        if !found {
            return None;
        }
        let k = self.bvh.primitive_indices[hit.primitive_id as usize] as usize;
        Some(Hit {
            triangle: self.ids[k],
            t: hit.t - BACKOFF,
            front: self.normals[k].dot(ray.direction) < 0.0,
        })
    }

    /// [`Visibility::closest_hit`] by testing every triangle (for tests of the BVH path).
    pub fn closest_hit_brute_force(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        let wt = Watertight::new(origin, dir);
        let d = Vec3A::from(dir.as_vec3());
        let mut best: Option<Hit> = None;
        for k in 0..self.tris.len() {
            let t = self.hit_distance(&wt, k, dir, 0.0, best.map_or(f32::INFINITY, |b| b.t));
            if t.is_finite() && best.is_none_or(|b| t < b.t) {
                best = Some(Hit {
                    triangle: self.ids[k],
                    t,
                    front: self.normals[k].dot(d) < 0.0,
                });
            }
        }
        best
    }

    /// Distance along the ray of `wt` (which starts `start` before the caller's origin) to BVH
    /// triangle `k`, or infinity. A back face closer than [`Visibility::epsilon`] to the origin
    /// is a surface the origin lies on (within rounding: a sample on the edge of a concave
    /// corner lies in the plane of the adjoining wall) and that the ray leaves through its front
    /// side, so it does not stop the ray; a front face at any distance does.
    #[inline]
    fn hit_distance(&self, wt: &Watertight, k: usize, dir: DVec3, start: f32, tmax: f32) -> f32 {
        let t = wt.intersect(&self.tris[k], start, tmax);
        if t.is_finite()
            && t - start < self.epsilon
            && self.normals[k].dot(Vec3A::from(dir.as_vec3())) >= 0.0
        {
            f32::INFINITY
        } else {
            t
        }
    }

    /// True when a surface lies on the segment from `from` to `to` (both lifted off their
    /// surfaces by the caller).
    pub fn occluded(&self, from: DVec3, to: DVec3) -> bool {
        let delta = to - from;
        let len = delta.length();
        if len <= 0.0 {
            return false;
        }
        let dir = delta / len;
        let start = from - dir * BACKOFF as f64;
        let wt = Watertight::new(start, dir);
        let ray = Ray::new(
            Vec3A::from(start.as_vec3()),
            Vec3A::from(dir.as_vec3()),
            0.0,
            len as f32 + BACKOFF,
        );
        !self.bvh.ray_traverse_miss(ray, |r, id| {
            self.hit_distance(
                &wt,
                self.bvh.primitive_indices[id] as usize,
                dir,
                BACKOFF,
                r.tmax,
            )
        })
    }
}

/// Watertight ray/triangle intersection (Woop, Benthin and Wald, JCGT 2013): a ray through the
/// shared edge or vertex of two triangles hits at least one of them, so closed scenes do not leak
/// rays through their seams (obvhs's Möller–Trumbore test does).
struct Watertight {
    origin: [f32; 3],
    k: [usize; 3],
    shear: [f32; 3],
}

impl Watertight {
    fn new(origin: DVec3, dir: DVec3) -> Self {
        let d = dir.as_vec3();
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Watertight {
            origin: origin.as_vec3().to_array(),
            k: [kx, ky, kz],
            shear: [d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]],
        }
    }

    /// Distance to the triangle, or infinity when missed or outside `[tmin, tmax]`.
    #[inline]
    fn intersect(&self, tri: &Triangle, tmin: f32, tmax: f32) -> f32 {
        let [kx, ky, kz] = self.k;
        let [sx, sy, sz] = self.shear;
        let o = self.origin;
        let rel = |v: Vec3A| [v.x - o[0], v.y - o[1], v.z - o[2]];
        let (a, b, c) = (rel(tri.v0), rel(tri.v1), rel(tri.v2));
        let (ax, ay) = (a[kx] - sx * a[kz], a[ky] - sy * a[kz]);
        let (bx, by) = (b[kx] - sx * b[kz], b[ky] - sy * b[kz]);
        let (cx, cy) = (c[kx] - sx * c[kz], c[ky] - sy * c[kz]);
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            u = (cx as f64 * by as f64 - cy as f64 * bx as f64) as f32;
            v = (ax as f64 * cy as f64 - ay as f64 * cx as f64) as f32;
            w = (bx as f64 * ay as f64 - by as f64 * ax as f64) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return f32::INFINITY;
        }
        let det = u + v + w;
        if det == 0.0 {
            return f32::INFINITY;
        }
        let t = (u * (sz * a[kz]) + v * (sz * b[kz]) + w * (sz * c[kz])) / det;
        if t >= tmin && t <= tmax {
            t
        } else {
            f32::INFINITY
        }
    }
}

/// The ray epsilon for a grid whose largest coordinate is `extent`: a few hundred f32 ulps of the
/// coordinates, never below 1e-5 of a voxel.
pub fn ray_epsilon(extent: f64) -> f32 {
    (256.0 * f32::EPSILON as f64 * extent.max(1.0)).max(1e-5) as f32
}
