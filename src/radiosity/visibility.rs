//! Ray visibility through an 8-wide BVH over the scene's triangles, in grid coordinates (f32).
//! Two queries: the closest hit (hemisphere shooting) and occlusion of a segment (pairwise form
//! factors, patch clustering, the transfer's leak test).
//!
//! obvhs builds the tree (a compressed-wide BVH, its highest-quality preset); [`WideBvh`] keeps
//! its shape with exact f32 child boxes and traverses it with AVX2 slab tests (wide_bvh.rs).
//! Triangles are tested with a watertight intersection (no rays lost through shared edges).
//! Rays start `BACKOFF` behind their origin (see there). The closest hit is order-independent:
//! of two hits at the same distance (a shared edge) the lower leaf slot wins.

use super::geometry::Frame;
use super::watertight::{TriangleLanes, Watertight};
use super::wide_bvh::{BoxRay, ClosestLeaf, WideBvh};
use crate::scene::Scene;
use glam::{DVec3, Vec3A};
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use std::time::Duration;

/// The scene's non-degenerate triangles in a BVH.
pub struct Visibility {
    bvh: WideBvh,
    tris: Vec<Triangle>,
    /// Scene triangle index of each BVH triangle.
    ids: Vec<u32>,
    /// The triangle of every BVH primitive slot, in leaf order (a triangle split into several
    /// boxes appears once per box): a leaf's triangles are contiguous in memory and reached
    /// without the `primitive_indices` indirection.
    slots: Vec<Slot>,
    /// The slots' triangles by component, for four-at-a-time leaf tests.
    lanes: TriangleLanes,
    /// Smallest ray parameter accepted, in grid units (above f32 self-intersection noise).
    pub epsilon: f32,
}

/// Rays start `BACKOFF` behind their origin and only hits at or beyond `BACKOFF` count. (obvhs's
/// own CWBVH traversal, used until the wide BVH replaced it, clamps entry distances to an absolute
/// 1e-4 and lost nearer hits; the offset stays so that every distance is the one it measured.)
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
        let slots: Vec<Slot> = bvh
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
        let bvh = WideBvh::from_cwbvh(&bvh, |i| {
            let v: &[Vec3A; 3] = &slots[i].v;
            (
                v[0].min(v[1]).min(v[2]).to_array(),
                v[0].max(v[1]).max(v[2]).to_array(),
            )
        });
        let lanes = TriangleLanes::new(&slots.iter().map(|s| s.v).collect::<Vec<_>>());
        Visibility {
            bvh,
            lanes,
            tris,
            ids: triangles.to_vec(),
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
        let d = Vec3A::from(dir.as_vec3());
        let ray = BoxRay::new(start.as_vec3().to_array(), d.to_array());
        let mut leaf = Closest {
            vis: self,
            wt: &wt,
            d,
            best: u32::MAX,
        };
        let t = self.bvh.closest(&ray, BACKOFF, f32::INFINITY, &mut leaf);
        let slot = self.slots.get(leaf.best as usize)?;
        Some(Hit {
            triangle: self.ids[slot.k as usize],
            t: t - BACKOFF,
            front: slot.normal.dot(d) < 0.0,
        })
    }

    /// [`Visibility::closest_hit`] by testing every triangle slot in order with the scalar test:
    /// the same answer bit for bit (tests/radiosity_visibility.rs), without the tree.
    pub fn closest_hit_brute_force(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        let start = origin - dir * BACKOFF as f64;
        let wt = Watertight::new(start, dir);
        let d = Vec3A::from(dir.as_vec3());
        let mut best: Option<(f32, &Slot)> = None;
        for slot in &self.slots {
            let tmax = best.map_or(f32::INFINITY, |b| b.0);
            let t = self.slot_distance(&wt, slot, d, BACKOFF, tmax);
            if t < tmax {
                best = Some((t, slot));
            }
        }
        best.map(|(t, slot)| Hit {
            triangle: self.ids[slot.k as usize],
            t: t - BACKOFF,
            front: slot.normal.dot(d) < 0.0,
        })
    }

    /// [`Visibility::occluded`] by testing every triangle slot with the scalar test.
    pub fn occluded_brute_force(&self, from: DVec3, to: DVec3) -> bool {
        let delta = to - from;
        let len = delta.length();
        if len <= 0.0 {
            return false;
        }
        let dir = delta / len;
        let wt = Watertight::new(from - dir * BACKOFF as f64, dir);
        let d = Vec3A::from(dir.as_vec3());
        let tmax = len as f32 + BACKOFF;
        self.slots
            .iter()
            .any(|slot| self.slot_distance(&wt, slot, d, BACKOFF, tmax).is_finite())
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

    /// Whether a finite distance `t` of the watertight test to slot `s` stops the ray: the rule
    /// of [`Visibility::slot_distance`].
    #[inline(always)]
    fn counts(&self, s: u32, t: f32, d: Vec3A) -> bool {
        t.is_finite() && (t - BACKOFF >= self.epsilon || self.slots[s as usize].normal.dot(d) < 0.0)
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
        let d = Vec3A::from(dir.as_vec3());
        let ray = BoxRay::new(start.as_vec3().to_array(), d.to_array());
        let tmax = len as f32 + BACKOFF;
        self.bvh.any(&ray, BACKOFF, tmax, |first, count| {
            let ts = self
                .lanes
                .intersect4(&wt, first as usize, count as usize, BACKOFF, tmax);
            (0..count as usize).any(|k| self.counts(first + k as u32, ts[k], d))
        })
    }
}

/// The closest-hit leaf test: the watertight distance to each slot's triangle; of equal
/// distances the lower slot wins, so the answer does not depend on the traversal order.
struct Closest<'a> {
    vis: &'a Visibility,
    wt: &'a Watertight,
    d: Vec3A,
    best: u32,
}

impl ClosestLeaf for Closest<'_> {
    #[inline(always)]
    fn leaf(&mut self, first: u32, count: u32, mut tmax: f32) -> f32 {
        let ts = self
            .vis
            .lanes
            .intersect4(self.wt, first as usize, count as usize, BACKOFF, tmax);
        for (k, &t) in ts.iter().enumerate().take(count as usize) {
            let s = first + k as u32;
            if !self.vis.counts(s, t, self.d) {
                continue;
            }
            if t < tmax || (t == tmax && s < self.best) {
                tmax = t;
                self.best = s;
            }
        }
        tmax
    }
}

/// A BVH primitive slot: its triangle's vertices (grid coordinates), unit normal and index
/// in the BVH's triangle list.
struct Slot {
    v: [Vec3A; 3],
    normal: Vec3A,
    k: u32,
}

/// The ray epsilon for a grid whose largest coordinate is `extent`: a few hundred f32 ulps of the
/// coordinates, never below 1e-5 of a voxel.
pub fn ray_epsilon(extent: f64) -> f32 {
    (256.0 * f32::EPSILON as f64 * extent.max(1.0)).max(1e-5) as f32
}
