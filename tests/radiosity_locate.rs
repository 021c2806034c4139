//! The patch locator's nearest-piece search against a brute-force scan.

use glam::DVec3;
use proptest::prelude::*;
use relume::radiosity::fixtures;
use relume::radiosity::geometry;
use relume::radiosity::locate::PatchLocator;
use relume::radiosity::voxelize::{voxelize, Resolution, VoxelizeParams};
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
