//! relume's ray tracer against Embree 4 (`embreex` on PyPI, a cross-check tool only): the exact
//! rays the hemisphere form-factor estimator casts on the Cornell box and on a random triangle
//! soup, traced by both; every ray must hit the same triangle at the same distance (1e-5
//! relative), or miss in both. A ray through an edge or vertex shared by several triangles may
//! name either; it then counts as agreeing when the distances agree. Hits closer to the
//! origin than relume's ray epsilon are not compared (relume passes through back faces there
//! by design; at most 1 in 1,000 rays: measured 4 of 12,672 on the Cornell box and 7 of 67,136
//! on the soup).

use crate::common;

#[path = "../support/embree_rays.rs"]
mod embree_rays;

use common::{python, repo, require_python};
use embree_rays::{
    context, f32_rays, f32_segments, hemisphere_rays, pairwise_segments, write_for_embree,
    write_segments, write_triangles,
};
use glam::Vec3;
use relume::raytrace::visibility::{Ray, BACKOFF};
use relume::scene::Scene;
use std::path::Path;

const EMBREE: &str = r#"
import sys, numpy as np
from embreex import rtcore_scene as rtcs
from embreex.mesh_construction import TriangleMesh
d = sys.argv[1]
tris = np.load(d + '/tris.npy')
o = np.load(d + '/origins.npy')
v = np.load(d + '/dirs.npy')
scene = rtcs.EmbreeScene()
TriangleMesh(scene=scene, vertices=tris)
r = scene.run(o, v, output=1)
prim = r['primID'].astype(np.int64)
t = np.where(prim >= 0, r['tfar'], -1.0).astype(np.float64)
np.save(d + '/embree.npy', np.stack([prim.astype(np.float64), t], axis=1))
"#;

/// Trace the hemisphere rays of every patch of `scene` (`k` per patch) with relume and Embree;
/// returns (rays, hits, disagreements), relume's hits and disagreements counted for both of its
/// entry points (so up to twice the rays).
fn compare(scene: &Scene, target: u32, k: usize, dir: &Path) -> (usize, usize, usize) {
    let (ctx, rays) = hemisphere_rays(scene, target, k, 7);
    // relume starts its f32 ray BACKOFF behind the origin (obvhs's near-hit cut-off,
    // src/raytrace/visibility.rs), rounded separately from the f32 origin Embree gets: the two
    // starts differ by up to an f32 ulp of the coordinates, which moves a hit along the ray by
    // that over |cos θ| (θ between the ray and the triangle's normal). Embree has no near limit
    // to give it the same start without it hitting the surface the ray leaves.
    let (ids, tris) = write_for_embree(dir, &ctx, &rays);
    let n = rays.len() as u64;
    python(EMBREE, &[dir.to_str().unwrap()]);
    let (shape, embree) = {
        // numpy wrote f64: read the raw little-endian values past the header.
        let bytes = std::fs::read(dir.join("embree.npy")).unwrap();
        let header = u16::from_le_bytes([bytes[8], bytes[9]]) as usize + 10;
        let v: Vec<f64> = bytes[header..]
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        ((v.len() / 2) as u64, v)
    };
    assert_eq!(shape, n);
    let (mut hits, mut off, mut near) = (0, 0, 0);
    let f32_rays = f32_rays(&rays);
    for (r, (origin, dirv)) in rays.iter().enumerate() {
        let (prim, t) = (embree[2 * r], embree[2 * r + 1]);
        // Within one ray epsilon of the origin relume passes through back faces by design: they
        // are the surface the ray leaves, within rounding (docs/radiosity.md, form_factors).
        // In a soup, triangles cross each other there; Embree stops at them.
        if prim >= 0.0 && t < ctx.vis.epsilon as f64 {
            near += 1;
            continue;
        }
        // The stage's call (f64 origin and direction) and the f32 ray Embree itself gets (what
        // benches/visibility_embree.rs times).
        let (o32, d32) = f32_rays[r];
        let f32_ray = Ray::from_f32(o32, d32, f32::INFINITY);
        for ours in [
            ctx.vis.closest_hit(*origin, *dirv),
            ctx.vis.trace_closest(&f32_ray),
        ] {
            match ours {
                None => {
                    if prim >= 0.0 {
                        off += 1;
                        eprintln!(
                            "ray {r}: relume misses, embree triangle {} t {t}",
                            ids[prim as usize]
                        );
                    }
                }
                Some(h) => {
                    hits += 1;
                    if prim < 0.0 {
                        off += 1;
                        eprintln!(
                            "ray {r}: relume triangle {} t {}, embree misses",
                            h.triangle, h.t
                        );
                        continue;
                    }
                    let tri = &tris[prim as usize];
                    let (a, b, c) = (Vec3::from(tri[0]), Vec3::from(tri[1]), Vec3::from(tri[2]));
                    let normal = (b - a).cross(c - a).normalize();
                    let cos = (normal.dot(dirv.as_vec3()) as f64).abs().max(1e-6);
                    let ulp = (origin.abs().max_element() as f32 + BACKOFF).to_bits();
                    let ulp = (f32::from_bits(ulp + 1) - f32::from_bits(ulp)) as f64;
                    let tol = 1e-5 * t.abs().max(1.0) + 2.0 * ulp / cos;
                    // Different triangles are the same answer at a shared edge (equal distances).
                    if (h.t as f64 - t).abs() > tol {
                        off += 1;
                        if off <= 5 {
                            eprintln!(
                                "ray {r}: relume triangle {} t {}, embree triangle {} t {t}",
                                h.triangle, h.t, ids[prim as usize]
                            );
                        }
                    }
                }
            }
        }
    }
    eprintln!("  {near} Embree hits closer than the ray epsilon to the origin, not compared");
    assert!(near * 1000 <= rays.len(), "{near} near-origin hits");
    (rays.len(), hits, off)
}

/// The two scenes compared: the Cornell box (32 triangles, in metres) and a random soup of
/// 2,000 triangles.
fn scenes() -> (Scene, Scene) {
    let (cornell, _) = relume::scene::load_scene(
        &repo().join("scenes/cornell-box/cornell_box.obj"),
        relume::scene::SceneOptions { scale: 0.001 },
    )
    .unwrap();
    (cornell, crate::fixtures::random_soup(2000, 11))
}

#[test]
fn relume_and_embree_hit_the_same_triangles_at_the_same_distances() {
    if !require_python(&["numpy", "embreex"]) {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let (cornell, soup) = scenes();
    for (name, scene, target) in [("cornell", &cornell, 400), ("soup", &soup, 2000)] {
        let dir = tmp.path().join(name);
        std::fs::create_dir(&dir).unwrap();
        let (rays, hits, off) = compare(scene, target, 32, &dir);
        eprintln!("{name}: {rays} hemisphere rays, {hits} hits, {off} disagreements with Embree");
        assert!(hits > rays / 2, "{name}: too few hits to compare ({hits})");
        assert_eq!(off, 0, "{name}: {off} of {rays} rays disagree with Embree");
    }
}

const EMBREE_OCCLUDED: &str = r#"
import sys, numpy as np
from embreex import rtcore_scene as rtcs
from embreex.mesh_construction import TriangleMesh
d = sys.argv[1]
scene = rtcs.EmbreeScene()
TriangleMesh(scene=scene, vertices=np.load(d + '/tris.npy'))
o = np.load(d + '/seg_origins.npy'); v = np.load(d + '/seg_dirs.npy'); l = np.load(d + '/seg_lengths.npy')
r = np.asarray(scene.run(o, v, dists=l, query='OCCLUDED'))
np.save(d + '/occluded.npy', (r != -1).astype(np.float32))
"#;

/// The occlusion test against Embree's on the segments the pairwise estimator casts
/// (`pairwise::pair_rays`): each segment occluded for both or for neither. The two start a
/// segment at points that differ by an f32 ulp (see `compare`) and Embree tests it from t = 0
/// where relume starts `BACKOFF` behind, so a segment that ends within rounding of a surface
/// may go either way: at most 1 in 10,000 may disagree (measured: 0 of 37,256 on the Cornell
/// box and 0 of 27,643 on the soup; the benchmark's furnished room, 119,239 segments, differs in
/// its occluded count by 2).
#[test]
fn relume_and_embree_agree_on_which_pairwise_segments_are_occluded() {
    if !require_python(&["numpy", "embreex"]) {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let (cornell, soup) = scenes();
    for (name, scene, target) in [("cornell", &cornell, 1024), ("soup", &soup, 2000)] {
        let dir = tmp.path().join(name);
        std::fs::create_dir(&dir).unwrap();
        let ctx = context(scene, target);
        write_triangles(&dir, &ctx);
        let segments = pairwise_segments(&ctx, 4, 16, 3);
        write_segments(&dir, &segments);
        python(EMBREE_OCCLUDED, &[dir.to_str().unwrap()]);
        let (_, embree) = relume::baked::npy::read_npy_f32(&dir.join("occluded.npy")).unwrap();
        assert_eq!(embree.len(), segments.len());
        // The stage's call (f64 endpoints) and the f32 segment Embree itself gets (what
        // benches/visibility_embree.rs times).
        let stage: Vec<bool> = segments
            .iter()
            .map(|(a, b)| ctx.vis.occluded(*a, *b))
            .collect();
        let f32_api: Vec<bool> = f32_segments(&segments)
            .iter()
            .map(|&(o, d, l)| ctx.vis.trace_occluded(&Ray::from_f32(o, d, l)))
            .collect();
        for (api, ours) in [("f64 endpoints", stage), ("f32 segments", f32_api)] {
            let occluded = ours.iter().filter(|&&o| o).count();
            let off = ours
                .iter()
                .zip(&embree)
                .filter(|(o, e)| **o != (**e > 0.5))
                .count();
            eprintln!(
                "{name}, {api}: {} pairwise segments, {occluded} occluded, {off} disagreements with Embree",
                segments.len()
            );
            // Both answers occur in numbers, or the comparison says little.
            assert!(occluded > segments.len() / 20 && occluded < segments.len() * 19 / 20);
            assert!(
                off * 10_000 <= segments.len(),
                "{name}, {api}: {off} disagree"
            );
        }
    }
}
