//! Transport matrices: furnace tests (k finite and infinite), S_1 = M, S_k → S_∞, agreement with
//! the f64 Gauss–Seidel reference, and the extremes (ρ = 0, 0.999, 1; memory budget).

use crate::fixtures;
use proptest::prelude::*;
use relume::progress::Silent;
use relume::radiosity::formfactor::{form_factors, Estimator, FormFactorParams};
use relume::radiosity::patches::voxelize::{voxelize, Resolution, VoxelizeParams};
use relume::radiosity::transport::reference::gauss_seidel;
use relume::radiosity::transport::{
    transport, Bounces, InfiniteSolver, Power, Transport, TransportParams, F32_ACCEPT,
};
use relume::scene::Scene;

const BIG: u64 = 1 << 40;

/// Patches and hemisphere form factors (512 rays: every F_ij = hits/512 is exact in f32, so
/// closed-box rows sum to exactly 1).
/// (albedo, emission, F, n).
type Baked = (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<f32>, usize);

fn bake(scene: &Scene, resolution: Resolution) -> Baked {
    let set = voxelize(
        scene,
        &VoxelizeParams {
            resolution,
            samples_per_patch: 1,
        },
    )
    .unwrap();
    let f = form_factors(
        scene,
        &set,
        &FormFactorParams {
            estimator: Estimator::Hemisphere,
            samples: 512,
            seed: 4,
        },
        &Silent,
    )
    .unwrap();
    let albedo = set.patches.iter().map(|p| p.albedo).collect();
    let emission = set.patches.iter().map(|p| p.emission).collect();
    (albedo, emission, f.values, f.n)
}

fn run(
    f: &[f32],
    n: usize,
    albedo: &[[f32; 3]],
    bounces: Bounces,
    power: Power,
) -> relume::Result<Transport> {
    transport(
        f,
        n,
        albedo,
        &TransportParams {
            bounces,
            power,
            max_memory: BIG,
            solver: Default::default(),
        },
        &Silent,
    )
}

fn furnace_box(rho: f32) -> (Vec<[f32; 3]>, Vec<f32>, usize) {
    let scene = fixtures::closed_box([1.0, 0.5, 0.75], rho, 1.0);
    let (albedo, _, f, n) = bake(&scene, Resolution::VoxelSize(0.25));
    (albedo, f, n)
}

#[test]
fn furnace_gives_the_geometric_series() {
    let rho = 0.6f64;
    let (albedo, f, n) = furnace_box(rho as f32);
    let e = vec![1.0; n];
    let t = run(&f, n, &albedo, Bounces::Infinite, Power::Auto).unwrap();
    assert_eq!(t.channels, 1, "grey scene: one channel");
    // B = E / (1 − ρ), so S_∞ E = E ρ / (1 − ρ).
    for v in t.apply(0, &e) {
        assert!((v - rho / (1.0 - rho)).abs() < 1e-4, "{v}");
    }
    for k in 1..=6u32 {
        let want = rho * (1.0 - rho.powi(k as i32)) / (1.0 - rho);
        for power in [Power::Horner, Power::Doubling] {
            let t = run(&f, n, &albedo, Bounces::Finite(k), power).unwrap();
            for v in t.apply(0, &e) {
                assert!((v - want).abs() < 1e-5, "k={k} {power:?}: {v} vs {want}");
            }
        }
    }
}

#[test]
#[allow(clippy::needless_range_loop)] // indices name matrix entries
fn one_bounce_is_m_and_more_bounces_converge_to_infinity() {
    let scene = relume::scene::load_scene(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes/cornell-box/cornell_box.obj"),
        relume::scene::SceneOptions { scale: 0.001 },
    )
    .unwrap()
    .0;
    let (albedo, emission, f, n) = bake(&scene, Resolution::TargetPatches(250));
    let s1 = run(&f, n, &albedo, Bounces::Finite(1), Power::Auto).unwrap();
    assert_eq!(s1.channels, 3);
    for c in 0..3 {
        for i in 0..n {
            for j in 0..n {
                assert_eq!(s1.data[c * n * n + i * n + j], albedo[i][c] * f[i * n + j]);
            }
        }
    }
    let inf = run(&f, n, &albedo, Bounces::Infinite, Power::Auto).unwrap();
    let rho_max = albedo.iter().flatten().copied().fold(0f32, f32::max) as f64;
    let mut last = f64::INFINITY;
    for k in [1u32, 2, 4, 8, 16, 32] {
        let t = run(&f, n, &albedo, Bounces::Finite(k), Power::Auto).unwrap();
        let gap = t
            .data
            .iter()
            .zip(&inf.data)
            .map(|(a, b)| (a - b).abs() as f64)
            .fold(0.0, f64::max);
        assert!(gap < last, "k={k}: gap {gap} did not shrink");
        // ‖Σ_{h>k} M^h‖_∞ ≤ ρ^{k+1} / (1 − ρ) bounds every entry.
        assert!(
            gap <= rho_max.powi(k as i32 + 1) / (1.0 - rho_max) + 1e-5,
            "k={k}: {gap}"
        );
        last = gap;
    }
    // Auto stops once a bounce adds less than the tolerance.
    let auto = run(&f, n, &albedo, Bounces::Auto(1e-4), Power::Auto).unwrap();
    assert!(
        auto.bounces.iter().all(|&k| k > 3 && k < 60),
        "{:?}",
        auto.bounces
    );
    let gap = auto
        .data
        .iter()
        .zip(&inf.data)
        .map(|(a, b)| (a - b).abs())
        .fold(0f32, f32::max);
    assert!(gap < 1e-3, "{gap}");
    // Agreement with the f64 Gauss–Seidel reference of B = E + M B, per channel.
    for c in 0..3 {
        let e: Vec<f64> = emission
            .iter()
            .map(|l| std::f64::consts::PI * l[c] as f64)
            .collect();
        let rho: Vec<f64> = albedo.iter().map(|a| a[c] as f64).collect();
        let reference = gauss_seidel(&f, &rho, &e, 1e-12, 10_000).unwrap();
        let top = reference.b.iter().copied().fold(0.0, f64::max);
        let b: Vec<f64> = inf
            .apply(c, &e)
            .iter()
            .zip(&e)
            .map(|(s, e)| s + e)
            .collect();
        for (x, y) in b.iter().zip(&reference.b) {
            assert!((x - y).abs() <= 1e-4 * top, "channel {c}: {x} vs {y}");
        }
        // Finite k against k explicit products in f64.
        let k = 5;
        let mut term = e.clone();
        let mut sum = vec![0.0; n];
        for _ in 0..k {
            term = (0..n)
                .map(|i| rho[i] * (0..n).map(|j| f[i * n + j] as f64 * term[j]).sum::<f64>())
                .collect();
            for (s, t) in sum.iter_mut().zip(&term) {
                *s += t;
            }
        }
        let t = run(&f, n, &albedo, Bounces::Finite(k), Power::Auto).unwrap();
        for (x, y) in t.apply(c, &e).iter().zip(&sum) {
            assert!((x - y).abs() <= 1e-5 * top, "k=5 channel {c}: {x} vs {y}");
        }
    }
}

#[test]
fn extremes_of_albedo() {
    // ρ = 0: no light ever bounces, S is exactly zero.
    let (albedo, f, n) = furnace_box(0.0);
    for b in [
        Bounces::Finite(3),
        Bounces::Finite(8),
        Bounces::Infinite,
        Bounces::Auto(1e-6),
    ] {
        let t = run(&f, n, &albedo, b, Power::Auto).unwrap();
        assert!(t.data.iter().all(|&v| v == 0.0), "{b:?}");
    }
    // ρ = 0.999 in a closed box: finite, near the furnace value 999.
    let (albedo, f, n) = furnace_box(0.999);
    let t = run(&f, n, &albedo, Bounces::Infinite, Power::Auto).unwrap();
    assert!(t.data.iter().all(|v| v.is_finite() && *v >= 0.0));
    for v in t.apply(0, &vec![1.0; n]) {
        assert!((v - 999.0).abs() < 0.01 * 999.0, "{v}");
    }
    // ρ = 1 in a closed box: infinite bounces diverge and are refused (never NaN).
    let (albedo, f, n) = furnace_box(1.0);
    for b in [Bounces::Infinite, Bounces::Auto(1e-3)] {
        let e = run(&f, n, &albedo, b, Power::Auto).unwrap_err();
        let m = e.to_string();
        assert!(
            m.contains("spectral radius") && m.contains("Finite(k)"),
            "{m}"
        );
        assert_eq!(e.exit_code(), relume::error::exit::INPUT);
    }
    // Finitely many bounces stay finite: S_3 · 1 = 3.
    let t = run(&f, n, &albedo, Bounces::Finite(3), Power::Auto).unwrap();
    for v in t.apply(0, &vec![1.0; n]) {
        assert!((v - 3.0).abs() < 1e-4, "{v}");
    }
}

#[test]
fn memory_budget_is_checked_before_allocating() {
    let (albedo, f, n) = furnace_box(0.5);
    let e = transport(
        &f,
        n,
        &albedo,
        &TransportParams {
            bounces: Bounces::Infinite,
            power: Power::Auto,
            max_memory: 1000,
            solver: Default::default(),
        },
        &Silent,
    )
    .unwrap_err();
    assert_eq!(e.exit_code(), relume::error::exit::LIMIT);
    assert!(e.to_string().contains("over the budget"), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// For random sub-stochastic F and albedo: Horner = doubling, S_{a+b} = S_a + M^a S_b via
    /// S_{a+1} = M + M S_a, and S_k → S_∞.
    #[test]
    fn power_sums_obey_their_laws(
        seed in any::<u64>(),
        n in 2usize..24,
        k in 1u32..13,
    ) {
        let mut x = seed | 1;
        let mut next = || { x ^= x << 13; x ^= x >> 7; x ^= x << 17; (x >> 11) as f64 / (1u64 << 53) as f64 };
        let mut f = vec![0f32; n * n];
        for i in 0..n {
            let row: Vec<f64> = (0..n).map(|j| if i == j { 0.0 } else { next() }).collect();
            let scale = next() / row.iter().sum::<f64>();
            for j in 0..n {
                f[i * n + j] = (row[j] * scale) as f32;
            }
        }
        let albedo: Vec<[f32; 3]> = (0..n).map(|_| [next() as f32 * 0.9, 0.5, 0.0]).collect();
        let h = run(&f, n, &albedo, Bounces::Finite(k), Power::Horner).unwrap();
        let d = run(&f, n, &albedo, Bounces::Finite(k), Power::Doubling).unwrap();
        prop_assert_eq!(h.channels, 3);
        for (a, b) in h.data.iter().zip(&d.data) {
            prop_assert!((a - b).abs() <= 1e-5 * (1.0 + a.abs()));
        }
        let k1 = run(&f, n, &albedo, Bounces::Finite(k + 1), Power::Horner).unwrap();
        let m = run(&f, n, &albedo, Bounces::Finite(1), Power::Horner).unwrap();
        for c in 0..3 {
            let o = c * n * n;
            for i in 0..n {
                for j in 0..n {
                    let ms: f32 = (0..n).map(|l| m.data[o + i * n + l] * h.data[o + l * n + j]).sum();
                    let want = m.data[o + i * n + j] + ms;
                    prop_assert!((k1.data[o + i * n + j] - want).abs() <= 1e-5);
                }
            }
        }
        let inf = run(&f, n, &albedo, Bounces::Infinite, Power::Auto).unwrap();
        let far = run(&f, n, &albedo, Bounces::Finite(400), Power::Auto).unwrap();
        for (a, b) in far.data.iter().zip(&inf.data) {
            prop_assert!((a - b).abs() <= 1e-4);
        }
    }
}

fn infinite_with(f: &[f32], n: usize, albedo: &[[f32; 3]], solver: InfiniteSolver) -> Transport {
    transport(
        f,
        n,
        albedo,
        &TransportParams {
            bounces: Bounces::Infinite,
            power: Power::Auto,
            max_memory: BIG,
            solver,
        },
        &Silent,
    )
    .unwrap()
}

/// The largest |a − b| over the largest |b|.
fn rel_err(a: &[f32], b: &[f32]) -> f64 {
    let top = b.iter().fold(0f64, |m, v| m.max(v.abs() as f64));
    let worst = a
        .iter()
        .zip(b)
        .fold(0f64, |m, (x, y)| m.max((*x as f64 - *y as f64).abs()));
    worst / top
}

#[test]
fn the_f32_solve_matches_the_f64_reference_or_gives_way_to_it() {
    // The Cornell box (coloured: three channels) and closed furnaces from ρ = 0.5 to 0.999.
    let cornell = relume::scene::load_scene(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes/cornell-box/cornell_box.obj"),
        relume::scene::SceneOptions { scale: 0.001 },
    )
    .unwrap()
    .0;
    let mut cases = vec![(
        "cornell".to_string(),
        bake(&cornell, Resolution::TargetPatches(400)),
    )];
    for rho in [0.5f32, 0.9, 0.99, 0.999] {
        let scene = fixtures::closed_box([1.0, 0.5, 0.75], rho, 1.0);
        cases.push((
            format!("furnace {rho}"),
            bake(&scene, Resolution::VoxelSize(0.125)),
        ));
    }
    for (name, (albedo, _, f, n)) in &cases {
        let reference = infinite_with(f, *n, albedo, InfiniteSolver::F64);
        let auto = infinite_with(f, *n, albedo, InfiniteSolver::Auto);
        let forced = infinite_with(f, *n, albedo, InfiniteSolver::F32);
        let e_auto = rel_err(&auto.data, &reference.data);
        let e_f32 = rel_err(&forced.data, &reference.data);
        let (solver, estimate) = auto.solvers[0];
        let estimate_f32 = forced.solvers[0].1;
        eprintln!(
            "{name} (n = {n}): auto chose {solver:?}; f32 error {e_f32:.2e}, estimated {estimate_f32:.2e}"
        );
        // Whatever Auto chose is within the 1e-5 of the f64 reference.
        assert!(e_auto <= 1e-5, "{name}: {e_auto}");
        // The estimate tracks the real error: within a factor of 10 either way above the f32
        // rounding of S's entries (6e-8).
        assert!(
            e_f32 <= 10.0 * estimate_f32 + 1e-6 && estimate_f32 <= 10.0 * e_f32 + 1e-6,
            "{name}: error {e_f32} vs estimate {estimate_f32}"
        );
        // Auto keeps the f32 solve exactly when its estimate passes.
        assert_eq!(
            solver == InfiniteSolver::F32,
            estimate_f32 <= F32_ACCEPT,
            "{name}"
        );
        if solver == InfiniteSolver::F32 {
            assert_eq!(estimate, estimate_f32);
        }
    }
}
