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
    /// The triangle of every BVH primitive slot, in leaf order (a triangle split into several
    /// boxes appears once per box): a leaf's triangles are contiguous in memory and reached
    /// without the `primitive_indices` indirection.
    slots: Vec<Slot>,
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
        let normals: Vec<Vec3A> = tris.iter().map(|t| t.compute_normal()).collect();
        // obvhs's highest-quality preset: on the furnished room (78,324 triangles) it traces
        // 2.3x the rays per second of `slow_build` for 2x its build time (0.15 s against
        // 0.07 s), where the form-factor stage casts millions of rays (benches/visibility_embree.rs).
        let bvh = build_cwbvh_from_tris(
            &tris,
            BvhBuildParams::very_slow_build(),
            &mut Duration::default(),
        );
        let slots = bvh
            .primitive_indices
            .iter()
            .map(|&k| {
                let t = &tris[k as usize];
                Slot {
                    v: [t.v0, t.v1, t.v2],
                    normal: normals[k as usize],
                    k,
                }
            })
            .collect();
        Visibility {
            bvh,
            tris,
            ids: triangles.to_vec(),
            normals,
            slots,
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
        let d = ray.direction;
        let found = self.bvh.ray_traverse(ray, &mut hit, |r, id| {
            self.slot_distance(&wt, &self.slots[id], d, BACKOFF, r.tmax)
        });
        if !found {
            return None;
        }
        let slot = &self.slots[hit.primitive_id as usize];
        Some(Hit {
            triangle: self.ids[slot.k as usize],
            t: hit.t - BACKOFF,
            front: slot.normal.dot(d) < 0.0,
        })
    }

    /// [`Visibility::closest_hit`] by testing every triangle (for tests of the BVH path).
    pub fn closest_hit_brute_force(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        let wt = Watertight::new(origin, dir);
        let d = Vec3A::from(dir.as_vec3());
        let mut best: Option<Hit> = None;
        for k in 0..self.tris.len() {
            let t = &self.tris[k];
            let slot = Slot {
                v: [t.v0, t.v1, t.v2],
                normal: self.normals[k],
                k: k as u32,
            };
            let t = self.slot_distance(&wt, &slot, d, 0.0, best.map_or(f32::INFINITY, |b| b.t));
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

    /// Distance along the ray of `wt` (which starts `start` before the caller's origin) to the
    /// triangle of `slot`, or infinity. A back face closer than [`Visibility::epsilon`] to the origin
    /// is a surface the origin lies on (within rounding: a sample on the edge of a concave
    /// corner lies in the plane of the adjoining wall) and that the ray leaves through its front
    /// side, so it does not stop the ray; a front face at any distance does.
    #[inline]
    fn slot_distance(&self, wt: &Watertight, slot: &Slot, d: Vec3A, start: f32, tmax: f32) -> f32 {
        let t = wt.intersect(&slot.v, start, tmax);
        if t.is_finite() && t - start < self.epsilon && slot.normal.dot(d) >= 0.0 {
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
        let d = ray.direction;
        !self.bvh.ray_traverse_miss(ray, |r, id| {
            self.slot_distance(&wt, &self.slots[id], d, BACKOFF, r.tmax)
        })
    }
}

/// A BVH primitive slot: its triangle's vertices (grid coordinates), unit normal and index
/// in the BVH's triangle list.
struct Slot {
    v: [Vec3A; 3],
    normal: Vec3A,
    k: u32,
}

/// Watertight ray/triangle intersection (Woop, Benthin and Wald, JCGT 2013): a ray through the
/// shared edge or vertex of two triangles hits at least one of them, so closed scenes do not leak
/// rays through their seams (obvhs's Möller–Trumbore test does).
///
/// The paper's shear `(a[kx] − sx·a[kz], a[ky] − sy·a[kz], sz·a[kz])` of a vertex a (relative to
/// the origin) is taken as three dot products with rows holding 1, −s and 0 in the permuted
/// axes: each product by 1 or 0 is exact and adding an exact 0 changes nothing, so every value
/// is the paper's bit for bit (no FMA contraction in Rust), without indexing by kx, ky, kz.
struct Watertight {
    origin: Vec3A,
    rows: [Vec3A; 3],
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
        let row = |k: usize, kz_weight: f32| {
            let mut r = [0.0f32; 3];
            r[k] = 1.0;
            r[kz] = kz_weight;
            Vec3A::from_array(r)
        };
        let sz = 1.0 / d[kz];
        let mut z = [0.0f32; 3];
        z[kz] = sz;
        Watertight {
            origin: Vec3A::from(origin.as_vec3()),
            rows: [
                row(kx, -(d[kx] / d[kz])),
                row(ky, -(d[ky] / d[kz])),
                Vec3A::from_array(z),
            ],
        }
    }

    /// Distance to the triangle, or infinity when missed or outside `[tmin, tmax]`.
    #[inline]
    fn intersect(&self, v: &[Vec3A; 3], tmin: f32, tmax: f32) -> f32 {
        let [rx, ry, rz] = self.rows;
        let shear = |p: Vec3A| {
            let q = p - self.origin;
            (q.dot(rx), q.dot(ry), q.dot(rz))
        };
        let ((ax, ay, az), (bx, by, bz), (cx, cy, cz)) = (shear(v[0]), shear(v[1]), shear(v[2]));
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
        let t = (u * az + v * bz + w * cz) / det;
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
