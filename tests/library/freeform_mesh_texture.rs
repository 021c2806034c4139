//! A shape texture meshed by its carrier grid (`relume::freeform::mesh_texture`): the measured
//! two-sided distance to the exact surface (mesh → surface by projection on the field,
//! surface → mesh from the exact reference's crossings) within the tolerance on a plane
//! carrier (the bundled morph grid, both ends of its morph) and a sphere carrier (a rough
//! random grid, poles included); outward winding; the subdivision is the least that meets the
//! bound (one step coarser errs more); the real CLI reports the method.

use crate::common;

use relume::freeform::field::Field;
use relume::freeform::mesh::{coverage_distance, hausdorff_to_surface, polygonise_with_stats};
use relume::freeform::mesh::{Mesh, MeshParams};
use relume::scene::freeform::FreeformScene;
use std::path::Path;

fn params(tolerance: f64) -> MeshParams {
    // The box is ignored by the carrier-grid mesher.
    MeshParams {
        lo: [-2.0; 3],
        hi: [2.0; 3],
        tolerance,
    }
}

fn mesh(field: &Field, tol: f64) -> (Mesh, u32) {
    let (m, stats) = polygonise_with_stats(field, &params(tol)).unwrap();
    assert!(stats.subdivision >= 1, "carrier grid used");
    (m, stats.subdivision)
}

/// Signed volume of the mesh's triangles against `c` (positive: wound outward about c).
fn volume_about(m: &Mesh, c: [f64; 3]) -> f64 {
    let s = |a: [f64; 3]| [a[0] - c[0], a[1] - c[1], a[2] - c[2]];
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, d] = t.map(|i| s(m.positions[i as usize]));
            (a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0])
                + a[2] * (b[0] * d[1] - b[1] * d[0]))
                / 6.0
        })
        .sum()
}

#[test]
fn plane_carrier_mesh_is_within_tolerance_both_ways_at_both_ends_of_the_morph() {
    let scene = FreeformScene::load(Path::new("scenes/freeform/morph-grid.ron")).unwrap();
    let mut field = Field::compile(&scene.shape).unwrap();
    // Inside the grid's rectangle (x, z in [0, 8]), where the mesh ends.
    let (lo, hi) = ([0.05, -1.0, 0.05], [7.95, 1.0, 7.95]);
    for s in [0.0, 1.0] {
        field.set_morph(s);
        for tol in [0.02, 0.004] {
            let (m, k) = mesh(&field, tol);
            let h = hausdorff_to_surface(&field, &m, 10);
            let c = coverage_distance(&field, &m, lo, hi, 24);
            eprintln!(
                "morph {s} tol {tol}: k {k}, {} triangles, mesh→surface {h:.3e}, surface→mesh {c:.3e}",
                m.triangles.len()
            );
            assert!(h <= tol && c <= tol, "morph {s} tol {tol}: {h} / {c}");
            // Wound so that the normal points up (+y, outside = above the heights).
            let up: f64 = m
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, d] = t.map(|i| m.positions[i as usize]);
                    (b[2] - a[2]) * (d[0] - a[0]) - (b[0] - a[0]) * (d[2] - a[2])
                })
                .fold(f64::INFINITY, f64::min);
            assert!(up > 0.0, "a triangle faces down ({up})");
            // The least k: one step coarser breaks the bound the mesher uses, and errs more.
            if k > 1 {
                let coarser_tol = tol * (k as f64 / (k - 1) as f64).powi(2) * 1.01;
                let (mc, kc) = mesh(&field, coarser_tol);
                assert_eq!(kc, k - 1, "tolerance {coarser_tol}");
                assert!(hausdorff_to_surface(&field, &mc, 10) >= h);
            }
        }
    }
}

#[test]
fn sphere_carrier_mesh_is_within_tolerance_both_ways_poles_included() {
    // A rough 24x12 grid (neighbours independent) of heights in ±0.05 on a unit sphere.
    let v: Vec<String> = (0..288)
        .map(|i| format!("{:?}", 0.05 * (((i * 7919 + 13) % 101) as f64 / 50.0 - 1.0)))
        .collect();
    let text = format!(
        "Freeform(shape: Textured(carrier: Sphere(centre: (0.1, 0.2, -0.1), radius: 1.0), heights: Grid(width: 24, height: 12, values: [{}])))",
        v.join(", ")
    );
    let scene = FreeformScene::parse(Path::new("t.ron"), &text).unwrap();
    let field = Field::compile(&scene.shape).unwrap();
    let (lo, hi) = ([-1.2, -1.1, -1.4], [1.4, 1.5, 1.2]);
    for tol in [0.02, 0.005] {
        let (m, k) = mesh(&field, tol);
        let h = hausdorff_to_surface(&field, &m, 10);
        let c = coverage_distance(&field, &m, lo, hi, 32);
        eprintln!(
            "sphere tol {tol}: k {k}, {} triangles, mesh→surface {h:.3e}, surface→mesh {c:.3e}",
            m.triangles.len()
        );
        assert!(h <= tol && c <= tol, "tol {tol}: {h} / {c}");
        // Outward: the signed volume about the centre is that of a ball of radius ~1.
        let vol = volume_about(&m, [0.1, 0.2, -0.1]);
        assert!(
            (vol - 4.0 / 3.0 * std::f64::consts::PI).abs() < 0.3,
            "volume {vol}"
        );
    }
}

#[test]
fn cylinder_carrier_mesh_is_within_tolerance_both_ways() {
    // A rough 16x6 grid of heights in ±0.05 on a cylinder of radius 0.7, length 2.
    let v: Vec<String> = (0..96)
        .map(|i| format!("{:?}", 0.05 * (((i * 4099 + 7) % 89) as f64 / 44.0 - 1.0)))
        .collect();
    let text = format!(
        "Freeform(shape: Textured(carrier: Cylinder(base: (0.1, -1.0, 0.2), radius: 0.7, length: 2.0), heights: Grid(width: 16, height: 6, values: [{}])))",
        v.join(", ")
    );
    let scene = FreeformScene::parse(Path::new("t.ron"), &text).unwrap();
    let field = Field::compile(&scene.shape).unwrap();
    // Within the carrier's length, where the mesh ends.
    let (lo, hi) = ([-0.8, -0.95, -0.7], [1.0, 0.95, 1.1]);
    for tol in [0.02, 0.005] {
        let (m, k) = mesh(&field, tol);
        let h = hausdorff_to_surface(&field, &m, 10);
        let c = coverage_distance(&field, &m, lo, hi, 32);
        eprintln!(
            "cylinder tol {tol}: k {k}, {} triangles, mesh→surface {h:.3e}, surface→mesh {c:.3e}",
            m.triangles.len()
        );
        assert!(h <= tol && c <= tol, "tol {tol}: {h} / {c}");
        // Outward: the signed volume about the axis point midway is the tube's less its two
        // end cones, (2/3)·π·0.7²·2 ≈ 2.05 (the heights average near 0).
        let vol = volume_about(&m, [0.1, 0.0, 0.2]);
        let tube = 2.0 / 3.0 * std::f64::consts::PI * 0.98;
        assert!((vol - tube).abs() < 0.3, "volume {vol}");
    }
}

#[test]
fn the_cli_meshes_a_texture_by_its_grid_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.obj");
    let o = common::bake(
        dir.path(),
        &[
            "freeform",
            "mesh",
            common::data("scenes/freeform/morph-grid.ron")
                .to_str()
                .unwrap(),
            "--tolerance",
            "0.01",
            "--out",
            out.to_str().unwrap(),
            "--json",
        ],
    );
    common::expect_code(&o, 0);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["method"], "carrier-grid");
    // 16x16 samples, k = 2 (measured): 31x31 vertices, 2·30·30 triangles.
    assert_eq!(j["vertices"], 961);
    assert_eq!(j["triangles"], 1800);
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 1800);
}
