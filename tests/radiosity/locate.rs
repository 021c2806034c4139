//! The patch locator's nearest-piece search against a brute-force scan.

use crate::fixtures;
use glam::DVec3;
use proptest::prelude::*;
use relume::radiosity::formfactor::locate::PatchLocator;
use relume::radiosity::geometry;
use relume::radiosity::patches::voxelize::{voxelize, Resolution, VoxelizeParams};
use relume::radiosity::PatchSet;
use relume::scene::Scene;

/// Two 300-gon discs in voxels as large as the scene: each patch holds hundreds of pieces, so
/// the search prunes whole runs of pieces (16 to a run).
fn disc_set() -> (Scene, PatchSet) {
    let scene = fixtures::coaxial_discs(1.0, 0.7, 0.5, 300);
    let set = voxelize(
        &scene,
        &VoxelizeParams {
            resolution: Resolution::VoxelSize(0.8),
            samples_per_patch: 1,
        },
    )
    .unwrap();
    (scene, set)
}

/// A 300-triangle soup in voxels of 0.25: many voxels hold several patches of one orientation
/// (visibility clusters).
fn soup_set(seed: u64) -> (Scene, PatchSet) {
    let scene = fixtures::random_soup(300, seed);
    let set = voxelize(
        &scene,
        &VoxelizeParams {
            resolution: Resolution::VoxelSize(0.25),
            samples_per_patch: 1,
        },
    )
    .unwrap();
    (scene, set)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// The pruned search equals a full scan of the patch's pieces: the same distance, point and
    /// normal (the first piece among equals), for points near and far.
    #[test]
    fn nearest_equals_a_full_scan(x in -3.0f64..3.0, y in -2.0f64..2.0, z in -3.0f64..3.0) {
        let (scene, set) = disc_set();
        let loc = PatchLocator::new(&set, &scene);
        prop_assert!(set.patches.iter().any(|p| p.piece_count > 64));
        let p = DVec3::new(x, y, z);
        for (i, patch) in set.patches.iter().enumerate() {
            let mut want = (f64::INFINITY, p, DVec3::Z);
            for piece in set.patch_pieces(patch) {
                let poly: Vec<DVec3> = piece.vertices.iter().map(|&v| DVec3::from(v)).collect();
                let n = DVec3::from(piece.normal);
                let q = geometry::closest_point_on_polygon(p, &poly, n);
                let d = (q - p).length();
                if d < want.0 {
                    want = (d, q, n);
                }
            }
            prop_assert_eq!(loc.nearest(p, i), want);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]
    /// A ray hit's patch, found with the hit triangle's own pieces bounding the search, is the
    /// patch the plain search finds, on a soup whose voxels hold several patches of one
    /// orientation (visibility clusters).
    #[test]
    fn locating_a_hit_by_its_triangle_changes_no_answer(
        seed in 0u64..1000,
        points in prop::collection::vec((0usize..10_000, 0.0f64..1.0, 0.0f64..1.0), 200),
    ) {
        let (scene, set) = soup_set(seed);
        let loc = PatchLocator::new(&set, &scene);
        let frame = set.frame();
        let mut shared = 0;
        for (pick, u, v) in points {
            let t = (pick % scene.triangles.len()) as u32;
            let [a, b, c] = scene.corners(t as usize).map(|x| frame.to_grid(x.to_array()));
            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
            let p = a + (b - a) * u + (c - a) * v;
            let axis = loc.triangle_axis(t);
            let voxel = relume::radiosity::formfactor::locate::voxel_of(p, set.dims);
            shared += (loc.candidates(voxel, axis).len() > 1) as usize;
            prop_assert_eq!(loc.locate_hit(p, t), loc.locate(p, axis));
        }
        prop_assert!(shared > 0, "no point fell in a voxel with several patches");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]
    /// The nearest patch of a voxel (patches searched in the order of their runs' lower bounds,
    /// whole patches pruned) is the first of the voxel's candidates with the least full-scan
    /// distance, for points on and off the surfaces, in every voxel holding several patches of
    /// one orientation.
    #[test]
    fn nearest_in_voxel_equals_the_least_full_scan(
        seed in 0u64..1000,
        offsets in prop::collection::vec(prop::array::uniform3(-0.5f64..1.5), 8),
    ) {
        let (scene, set) = soup_set(seed);
        let loc = PatchLocator::new(&set, &scene);
        let mut groups: Vec<([u32; 3], u8)> = set.patches.iter().map(|p| (p.voxel, p.axis)).collect();
        groups.dedup();
        let mut shared = 0;
        for (voxel, axis) in groups {
            let voxel = voxel.map(|v| v as i64);
            if loc.candidates(voxel, axis).len() < 2 {
                continue;
            }
            shared += 1;
            for o in &offsets {
                let p = DVec3::from(std::array::from_fn(|a| voxel[a] as f64 + o[a]));
                let want = loc
                    .candidates(voxel, axis)
                    .map(|i| (i as u32, loc.nearest(p, i).0))
                    .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
                let got = loc.nearest_in_voxel(p, voxel, axis).map(|c| (c.0, c.1));
                prop_assert_eq!(got, want, "voxel {:?} axis {} point {}", voxel, axis, p);
            }
        }
        prop_assert!(shared > 0, "no voxel with several patches");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// A hit's patch from the per-triangle table is the full nearest-piece search's, for points
    /// on the hit triangle, on its edges and corners (seams between patches and voxel faces),
    /// and lifted off it by up to twice the on-surface tolerance (where the table hands over to
    /// the search), on soups whose voxels hold several patches of one orientation.
    #[test]
    fn the_hit_table_gives_the_searching_answer(
        seed in 0u64..1000,
        size in prop::sample::select(vec![0.25f64, 0.4]),
        points in prop::collection::vec(
            (0usize..10_000, 0.0f64..1.0, 0.0f64..1.0, 0usize..4, -2.0f64..2.0),
            300,
        ),
    ) {
        let scene = fixtures::random_soup(300, seed);
        let set = voxelize(
            &scene,
            &VoxelizeParams { resolution: Resolution::VoxelSize(size), samples_per_patch: 1 },
        )
        .unwrap();
        let loc = PatchLocator::new(&set, &scene);
        let frame = set.frame();
        let mut shared = 0;
        for (pick, u, v, kind, lift) in points {
            let t = (pick % scene.triangles.len()) as u32;
            let [a, b, c] = scene.corners(t as usize).map(|x| frame.to_grid(x.to_array()));
            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
            let n = (b - a).cross(c - a).normalize_or_zero();
            let p = match kind {
                0 => a + (b - a) * u + (c - a) * v,
                1 => a + (b - a) * u,
                2 => [a, b, c][pick % 3],
                _ => a + (b - a) * u + (c - a) * v + n * (lift * 1e-3),
            };
            let axis = loc.triangle_axis(t);
            let voxel = relume::radiosity::formfactor::locate::voxel_of(p, set.dims);
            shared += (loc.candidates(voxel, axis).len() > 1) as usize;
            prop_assert_eq!(loc.locate_hit(p, t), loc.locate_hit_searching(p, t), "t {} p {}", t, p);
        }
        prop_assert!(shared > 0, "no point fell in a voxel with several patches");
    }
}

/// The hemisphere rays' hits in the bundled scenes find the patch the full search finds.
#[test]
fn bundled_scenes_hits_find_the_searching_patch() {
    use relume::radiosity::formfactor::{hemisphere, Context};
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let scenes = [
        ("scenes/cornell-box/cornell_box.obj", 0.001, 600),
        ("scenes/generated/furnished-room.obj", 1.0, 1500),
        ("scenes/generated/door-ajar.obj", 1.0, 1500),
        ("scenes/generated/door-sealed.obj", 1.0, 1500),
    ];
    for (path, scale, target) in scenes {
        let scene =
            relume::scene::load_scene(&root.join(path), relume::scene::SceneOptions { scale })
                .unwrap()
                .0;
        let set = voxelize(
            &scene,
            &VoxelizeParams {
                resolution: Resolution::TargetPatches(target),
                samples_per_patch: 1,
            },
        )
        .unwrap();
        let ctx = Context::new(&scene, &set);
        let (mut hits, mut shared) = (0, 0);
        for i in 0..set.len() {
            for (origin, dir) in hemisphere::rays(&ctx, i, 64, 0) {
                let Some(hit) = ctx.vis.closest_hit(origin, dir) else {
                    continue;
                };
                if !hit.front {
                    continue;
                }
                let p = origin + dir * hit.t as f64;
                let axis = ctx.locator.triangle_axis(hit.triangle);
                let voxel = relume::radiosity::formfactor::locate::voxel_of(p, set.dims);
                shared += (ctx.locator.candidates(voxel, axis).len() > 1) as usize;
                hits += 1;
                assert_eq!(
                    ctx.locator.locate_hit(p, hit.triangle),
                    ctx.locator.locate_hit_searching(p, hit.triangle),
                    "{path}: patch {i}, hit {p} on triangle {}",
                    hit.triangle
                );
            }
        }
        assert!(
            hits > 0 && (path.contains("cornell") || shared > 0),
            "{path}: {hits} hits, {shared} shared"
        );
    }
}
