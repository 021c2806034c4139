//! The f32 twin of the freeform kernel: its widened bound is sound (holds every f64 value of
//! the field on the cell) and never culls a cell the f64 bound keeps (proptest over random
//! scenes and cells); the GPU (lavapipe here and in CI) returns the twin's hit mask, depths
//! and normals; and the twin's frames agree with the f64 caster's.

use crate::common;

use proptest::prelude::*;
use relume::freeform::bounds::{field_range, Bound, Work};
use relume::freeform::field::Field;
use relume::freeform::rmlrc::{camera_outside, cast, RmlrcParams};
use relume::freeform::twin::{field_range32, GpuField, View32};
use relume::freeform::twin_cast::cast32;
use relume::freeform::View;
use relume::scene::freeform::{FreeformCamera, FreeformScene};
use std::path::Path;

fn random_scene(seed: &[f64]) -> String {
    // A sphere (or ellipsoid) with a few bumps, minus a cylinder: CSG, cubes and hulls all used.
    let s = |i: usize| seed[i % seed.len()];
    let mut bumps = String::new();
    for k in 0..4 {
        bumps += &format!(
            "(shape: Sphere(radius: {:.3}), transform: (translate: ({:.3}, {:.3}, {:.3})), weight: {:.3}),",
            0.2 + 0.5 * s(k).abs(),
            s(k + 1),
            s(k + 2),
            s(k + 3),
            s(k + 4) * 2.0
        );
    }
    format!(
        "Freeform(shape: Difference(Surface(base: Ellipsoid(radii: ({:.3}, {:.3}, {:.3})), transform: (translate: ({:.3}, {:.3}, 0.0), rotate: ({:.1}, {:.1}, 0.0)), perturbations: [{bumps}]),
            Surface(base: Cylinder(radius: {:.3}), transform: (rotate: ({:.1}, 0.0, 0.0)))))",
        0.6 + s(5).abs(),
        0.6 + s(6).abs(),
        0.6 + s(7).abs(),
        s(8) * 0.5,
        s(9) * 0.5,
        s(10) * 90.0,
        s(11) * 90.0,
        0.1 + 0.3 * s(12).abs(),
        s(13) * 90.0
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]
    #[test]
    fn widened_f32_bound_is_sound_and_keeps_what_f64_keeps(
        seed in prop::collection::vec(-1.0f64..1.0, 16),
        eye in prop::array::uniform3(-6.0f64..6.0),
        tile in prop::array::uniform2(0u32..64),
        level in 0u32..6,
        s_frac in 0.0f64..1.0,
        ds_scale in 0.05f64..4.0,
    ) {
        prop_assume!(eye.iter().map(|x| x * x).sum::<f64>() > 4.0);
        let scene = FreeformScene::parse(Path::new("p.ron"), &random_scene(&seed)).unwrap();
        let field = Field::compile(&scene.shape).unwrap();
        let cam = FreeformCamera { eye, target: [0.0; 3], fov: 50.0, near: None, far: None };
        let view = View::new(&cam, 64, 64);
        let v32 = View32::of(&view);
        let gpu_field = GpuField::upload(&field, view.eye).unwrap();
        let size = 1u32 << level;
        let (tx, ty) = (tile[0] / size * size, tile[1] / size * size);
        let ex = [tx as f64, ((tx + size).min(64)) as f64];
        let ey = [ty as f64, ((ty + size).min(64)) as f64];
        let dist = eye.iter().map(|x| x * x).sum::<f64>().sqrt();
        let s0 = (dist * (0.5 + s_frac)).ln() - 0.6;
        let ds = view.pixel_angle() * size as f64 * ds_scale;
        let s = [s0, s0 + ds];
        let c64 = view.cell([view.screen_x(ex[0]), view.screen_x(ex[1])], [view.screen_y(ey[1]), view.screen_y(ey[0])], s);
        let c32 = v32.cell(
            [v32.screen_x(ex[0] as f32), v32.screen_x(ex[1] as f32)],
            [v32.screen_y(ey[1] as f32), v32.screen_y(ey[0] as f32)],
            [s[0] as f32, s[1] as f32],
        );
        let r64 = field_range(&field, &c64, Bound::Affine, &mut Work::default());
        let (lo, hi) = field_range32(&gpu_field, &c32);
        // Keeps what f64 keeps.
        if r64.straddles() {
            prop_assert!(lo <= 0.0 && hi >= 0.0, "f64 keeps {r64:?}, f32 culls [{lo}, {hi}]");
        }
        // Sound: the field's f64 values on points of the cell lie in the f32 bound.
        for k in 0..27 {
            let e = [(k % 3) as f64 - 1.0, ((k / 3) % 3) as f64 - 1.0, (k / 9) as f64 - 1.0];
            let eps = [e[0], e[1], e[2], e[0] * e[1], e[0] * e[2]];
            let p: [f64; 3] = std::array::from_fn(|a| c64.c[a] + (0..5).map(|j| eps[j] * c64.v[j][a]).sum::<f64>());
            let v = field.eval(p);
            prop_assert!(v >= lo as f64 && v <= hi as f64, "value {v} at {p:?} outside [{lo}, {hi}]");
        }
    }
}

/// Per pixel: GPU against twin (mask differences, worst depth and normal), twin against the f64
/// caster (mask differences, on-another-surface count, worst depth).
struct Agreement {
    mask_diff: usize,
    worst_depth: f32,
    worst_normal: f32,
    hit_pixels: usize,
    /// Hit pixels where the GPU's depth is off by more than 1e-4 relative or its normal by more
    /// than 1e-3 (not in the worst values).
    outliers: usize,
    f64_diff: usize,
    f64_other_surface: usize,
    worst_f64_depth: f64,
}

fn agreement(
    twin: &[Option<(f32, [f32; 3])>],
    gpu_hits: &[[f32; 4]],
    f64_hits: &[Option<f64>],
) -> Agreement {
    let mut a = Agreement {
        mask_diff: 0,
        worst_depth: 0.0,
        worst_normal: 0.0,
        hit_pixels: 0,
        outliers: 0,
        f64_diff: 0,
        f64_other_surface: 0,
        worst_f64_depth: 0.0,
    };
    for i in 0..twin.len() {
        let g = gpu_hits[i];
        match (twin[i], g[0] >= 0.0) {
            (Some((t, n)), true) => {
                a.hit_pixels += 1;
                let rel = (g[0] - t).abs() / t;
                let dn = (0..3).map(|k| (g[1 + k] - n[k]).abs()).fold(0.0, f32::max);
                if rel > 1e-4 || dn > 1e-3 {
                    a.outliers += 1;
                } else {
                    a.worst_depth = a.worst_depth.max(rel);
                    a.worst_normal = a.worst_normal.max(dn);
                }
            }
            (None, false) => {}
            _ => a.mask_diff += 1,
        }
        match (twin[i], f64_hits[i]) {
            (Some((t, _)), Some(r)) => {
                let rel = (t as f64 - r).abs() / r;
                if rel > 1e-3 {
                    a.f64_other_surface += 1;
                } else {
                    a.worst_f64_depth = a.worst_f64_depth.max(rel);
                }
            }
            (None, None) => {}
            _ => a.f64_diff += 1,
        }
    }
    a
}

#[test]
fn gpu_returns_the_twin_and_the_twin_the_f64_caster() {
    let Some(gpu) = common::gpu() else { return };
    let caster = relume::gpu::freeform_caster::FreeformCaster::new(&gpu).unwrap();
    for name in [
        "csg-holes.ron",
        "terrain-16.ron",
        "blobs-128.ron",
        "bench/terrain-256.ron",
    ] {
        let (field, camera) = common::freeform::bundled(name);
        let c = common::freeform::three_casts(&gpu, &caster, &field, &camera, (96, 72));
        let (twin, gpu_hits, f64_hits) = (c.twin, c.gpu, c.f64);
        let a = agreement(&twin, &gpu_hits, &f64_hits);
        eprintln!(
            "{name}: gpu vs twin: {} hit-mask differences, depth {:.2e} rel, normal {:.2e}, {} outliers of {} hits; twin vs f64: {} differences, depth {:.2e} rel ({} on another surface)",
            a.mask_diff, a.worst_depth, a.worst_normal, a.outliers, a.hit_pixels, a.f64_diff, a.worst_f64_depth, a.f64_other_surface
        );
        assert_eq!(a.mask_diff, 0, "{name}");
        // Depth within 1e-4 relative and normal within 1e-3 on every hit pixel (measured: depth
        // 0 and normal 6e-8 on csg-holes and terrain-16; on blobs-128, where the driver may
        // fuse multiply-adds the twin rounds twice, 6.6e-5 and 9.2e-4) — except on terrain-256,
        // whose field sums 256 overlapping cubic terms in f32: there the driver's roundings
        // pick another root than the twin's on 146 of 6,624 hit pixels (2.2 %; the twin itself
        // is on another surface than the f64 caster on 114), bounded at 5 %.
        let allowed = if name.contains("256") {
            a.hit_pixels * 5 / 100
        } else {
            0
        };
        assert!(
            a.outliers <= allowed,
            "{name}: {} of {} hits off",
            a.outliers,
            a.hit_pixels
        );
        // The twin against the f64 caster: hit/miss on all but 0.2 % of pixels (silhouettes,
        // where the widened f32 bound keeps a grazing cell the f64 one culls). Measured: 0, 0
        // and 9 of 6,912 (0.13 %, blobs-128).
        assert!(a.f64_diff * 500 <= twin.len(), "{name}: {}", a.f64_diff);
    }
}

/// Lavapipe ends an invocation's loops after 65,535 iterations in all, so the kernel splits
/// each level's depth walk into passes and each pixel's search into rounds that resume where
/// the last stopped. With a budget of 4,096 loop iterations per pass (16 times less than the
/// default) terrain-64 needs many of both, and must return what one uninterrupted search
/// returns: the twin's hits, to the same tolerances.
#[test]
fn a_search_split_into_rounds_returns_what_one_search_returns() {
    let Some(gpu) = common::gpu() else { return };
    let caster = relume::gpu::freeform_caster::FreeformCaster::new(&gpu)
        .unwrap()
        .with_pass_loops(4096);
    let params = RmlrcParams::default();
    let (field, camera) = common::freeform::bundled("bench/terrain-64.ron");
    let view = View::new(&camera, 96, 72);
    let v32 = View32::of(&view);
    let gf = GpuField::upload(&field, view.eye).unwrap();
    let prune = camera_outside(&field, &view, Bound::Affine);
    let twin = cast32(&gf, &v32, params.top_level, params.refine, prune);
    let out = caster
        .cast_levels(
            &gpu,
            &gf,
            &v32,
            params.top_level,
            params.refine,
            prune,
            None,
            true,
        )
        .unwrap();
    let (f64_hits, _) = cast(&field, &view, &params);
    let a = agreement(&twin, &out.hits, &f64_hits);
    eprintln!(
        "terrain-64 in {} tile passes and {} pixel rounds: {} mask differences, depth {:.2e}, normal {:.2e} over {} hits",
        out.tile_passes, out.pixel_rounds, a.mask_diff, a.worst_depth, a.worst_normal, a.hit_pixels
    );
    assert!(out.pixel_rounds >= 3, "{} rounds", out.pixel_rounds);
    assert!(out.tile_passes >= 10, "{} passes", out.tile_passes);
    // Every level's ranges equal the twin's exactly: the passes walk the same cells in order.
    let levels = relume::freeform::twin_cast::levels32(&gf, &v32, params.top_level, prune);
    assert_eq!(levels.len(), out.levels.len());
    for (l, (t, g)) in levels.iter().zip(&out.levels).enumerate() {
        let differ = t
            .iter()
            .zip(g)
            .filter(|(a, b)| (a[0] > a[1]) != (b[0] > b[1]) || (a[0] <= a[1] && a != b))
            .count();
        assert_eq!(differ, 0, "level {l}");
    }
    assert_eq!(a.mask_diff, 0);
    assert_eq!(a.outliers, 0);
}
