//! Polygonisation of freeform fields (`relume::freeform::mesh`) against independent values:
//! the analytic sphere (radius, volume 4/3·π), topology by Euler characteristic (sphere 2,
//! washer 0), manifoldness and winding by counting directed edges, the measured two-sided
//! distance to the exact surface on the bundled blobs scene, OBJ output read back by `tobj`.

use relume::freeform::field::Field;
use relume::freeform::mesh::{
    coverage_distance, hausdorff_to_surface, obj_bytes, polygonise, polygonise_with_stats,
    write_obj, Mesh, MeshParams,
};
use relume::scene::freeform::FreeformScene;
use std::collections::HashMap;
use std::path::Path;
use std::time::Instant;

fn field(shape: &str) -> Field {
    let text = format!("Freeform(shape: {shape})");
    let scene = FreeformScene::parse(Path::new("test.ron"), &text).unwrap();
    Field::compile(&scene.shape).unwrap()
}

fn scene_field(name: &str) -> Field {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes/freeform")
        .join(name);
    Field::compile(&FreeformScene::load(&path).unwrap().shape).unwrap()
}

fn params(lo: f64, hi: f64, tolerance: f64) -> MeshParams {
    MeshParams {
        lo: [lo; 3],
        hi: [hi; 3],
        tolerance,
    }
}

const SPHERE: &str = "Surface(base: Sphere(radius: 1.0))";
const WASHER: &str = "Difference(Intersection([Surface(base: Cylinder(radius: 1.0)), \
    Surface(base: Plane(normal: (0.0, 1.0, 0.0), offset: 0.3)), \
    Surface(base: Plane(normal: (0.0, -1.0, 0.0), offset: 0.3))]), \
    Surface(base: Cylinder(radius: 0.4)))";

/// Every directed edge once, its reverse once: closed, manifold along edges, consistently
/// wound. Returns the number of undirected edges.
fn check_closed_and_wound(mesh: &Mesh) -> usize {
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &mesh.triangles {
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[0] != t[2],
            "repeated index in {t:?}"
        );
        for e in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            *directed.entry(e).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "edge {a}->{b} used {n} times in one direction");
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "edge {a}->{b} has no opposite half: open or inconsistently wound"
        );
    }
    directed.len() / 2
}

fn euler(mesh: &Mesh) -> i64 {
    let e = check_closed_and_wound(mesh) as i64;
    let used: std::collections::HashSet<u32> = mesh.triangles.iter().flatten().copied().collect();
    assert_eq!(used.len(), mesh.positions.len(), "unreferenced vertices");
    mesh.positions.len() as i64 - e + mesh.triangles.len() as i64
}

/// Signed volume by the divergence theorem (positive for outward winding).
fn volume(mesh: &Mesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let cr = [
                b[1] * c[2] - b[2] * c[1],
                b[2] * c[0] - b[0] * c[2],
                b[0] * c[1] - b[1] * c[0],
            ];
            (a[0] * cr[0] + a[1] * cr[1] + a[2] * cr[2]) / 6.0
        })
        .sum()
}

fn area(mesh: &Mesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let (u, v) = (
                [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
            );
            let cr = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            0.5 * (cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]).sqrt()
        })
        .sum()
}

#[test]
fn unit_sphere_at_two_tolerances() {
    let f = field(SPHERE);
    for tol in [1e-2, 1e-3] {
        let t0 = Instant::now();
        let (mesh, stats) = polygonise_with_stats(&f, &params(-1.5, 1.5, tol)).unwrap();
        let secs = t0.elapsed().as_secs_f64();
        eprintln!(
            "sphere tol {tol:e}: {} triangles, {} vertices, {:.3} s, spacing {:.4}, \
             curvature {:.4}, {} passes, {} OBJ bytes",
            mesh.triangles.len(),
            mesh.positions.len(),
            secs,
            stats.spacing,
            stats.curvature,
            stats.passes,
            obj_bytes(&mesh)
        );
        // The analytic surface: every vertex on |p| = 1.
        for p in &mesh.positions {
            let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            assert!((r - 1.0).abs() <= tol, "vertex {p:?} at radius {r}");
        }
        // Curvature of the unit sphere is 1.
        assert!((stats.curvature - 1.0).abs() < 1e-6, "{}", stats.curvature);
        // Inscribed mesh within `tol` of the sphere: the volume lost is at most area × tol.
        let exact = 4.0 / 3.0 * std::f64::consts::PI;
        let v = volume(&mesh);
        assert!(
            v <= exact + 1e-9 && exact - v <= 4.0 * std::f64::consts::PI * tol,
            "{v}"
        );
        assert_eq!(euler(&mesh), 2, "sphere is closed, genus 0");
        // Measured distance, and the exact mesh → sphere distance of the sample points agree.
        let h = hausdorff_to_surface(&f, &mesh, 10);
        assert!(h <= tol, "Hausdorff {h} over tolerance {tol}");
        eprintln!("sphere tol {tol:e}: measured Hausdorff {h:.3e}");
    }
}

#[test]
fn sphere_samples_agree_with_the_analytic_distance() {
    // hausdorff_to_surface's Newton projection against 1 − |p| at the triangle centroids.
    let f = field(SPHERE);
    let mesh = polygonise(&f, &params(-1.5, 1.5, 2e-2)).unwrap();
    let worst = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let g: [f64; 3] = std::array::from_fn(|k| (a[k] + b[k] + c[k]) / 3.0);
            1.0 - (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt()
        })
        .fold(0.0, f64::max);
    let one = Mesh {
        positions: mesh.positions.clone(),
        triangles: mesh.triangles.clone(),
    };
    let h = hausdorff_to_surface(&f, &one, 1);
    assert!(worst > 0.0 && h >= worst - 1e-12, "{h} vs centroid {worst}");
    assert!(h <= 2e-2);
}

#[test]
fn washer_has_euler_characteristic_zero() {
    let f = field(WASHER);
    let tol = 5e-2;
    let (mesh, stats) = polygonise_with_stats(&f, &params(-1.3, 1.3, tol)).unwrap();
    eprintln!("washer tol {tol}: {} triangles", mesh.triangles.len());
    assert_eq!(euler(&mesh), 0, "a washer is a torus");
    // Its four circular edges are creases: the spacing falls back to the tolerance.
    assert!(stats.crease && stats.spacing <= tol);
    // Volume π(1 − 0.4²)·0.6; the mesh cuts the creases: within 2 %.
    let exact = std::f64::consts::PI * (1.0 - 0.16) * 0.6;
    let v = volume(&mesh);
    assert!((v - exact).abs() <= 0.02 * exact, "{v} vs {exact}");
    let h = hausdorff_to_surface(&f, &mesh, 6);
    assert!(h <= tol, "mesh → surface {h} over {tol}");
}

#[test]
fn blobs_mesh_within_tolerance_both_ways() {
    let f = scene_field("blobs-128.ron");
    let tol = 0.02;
    let (lo, hi) = ([-2.2; 3], [2.2; 3]);
    let t0 = Instant::now();
    let (mesh, stats) = polygonise_with_stats(
        &f,
        &MeshParams {
            lo,
            hi,
            tolerance: tol,
        },
    )
    .unwrap();
    eprintln!(
        "blobs-128 tol {tol}: {} triangles, {:.3} s, spacing {:.4}, curvature {:.3}, {} passes",
        mesh.triangles.len(),
        t0.elapsed().as_secs_f64(),
        stats.spacing,
        stats.curvature,
        stats.passes
    );
    check_closed_and_wound(&mesh);
    assert!(volume(&mesh) > 0.0, "outward winding");
    let t1 = Instant::now();
    let h = hausdorff_to_surface(&f, &mesh, 6);
    let t2 = Instant::now();
    let c = coverage_distance(&f, &mesh, lo, hi, 24);
    eprintln!(
        "blobs-128 tol {tol}: mesh→surface {h:.4e} ({:.2} s), surface→mesh {c:.4e} ({:.2} s)",
        (t2 - t1).as_secs_f64(),
        t2.elapsed().as_secs_f64()
    );
    assert!(h <= tol, "mesh → surface {h} over {tol}");
    assert!(c <= tol, "surface → mesh {c} over {tol}");
    // Every vertex is on the surface (field ≈ 0 relative to its gradient).
    for p in &mesh.positions {
        assert!(f.eval(*p).abs() < 1e-9, "{p:?}: {}", f.eval(*p));
    }
}

#[test]
fn output_is_the_same_for_any_thread_count() {
    let f = scene_field("blobs-128.ron");
    let p = params(-2.2, 2.2, 0.05);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| polygonise(&f, &p).unwrap())
    };
    let (one, three) = (run(1), run(3));
    assert!(!one.triangles.is_empty());
    assert_eq!(one, three);
}

#[test]
fn a_cut_surface_is_open_at_the_box() {
    // Half the sphere in the box (cut exactly at z = 0): a disc, V − E + F = 1, area near 2π.
    let f = field(SPHERE);
    let mesh = polygonise(
        &f,
        &MeshParams {
            lo: [-1.5, -1.5, 0.0],
            hi: [1.5, 1.5, 1.5],
            tolerance: 1e-2,
        },
    )
    .unwrap();
    let a = area(&mesh);
    assert!(
        (a - 2.0 * std::f64::consts::PI).abs() < 2.0 * std::f64::consts::PI * 1e-2,
        "{a}"
    );
    assert!(mesh.positions.iter().all(|p| p[2] >= 0.0));
    let mut directed = std::collections::HashSet::new();
    for t in &mesh.triangles {
        directed.extend([(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]);
    }
    let open = directed
        .iter()
        .filter(|&&(a, b)| !directed.contains(&(b, a)))
        .count();
    let edges = (directed.len() + open) / 2;
    let euler = mesh.positions.len() as i64 - edges as i64 + mesh.triangles.len() as i64;
    assert!(open > 0 && euler == 1, "open {open}, euler {euler}");
}

#[test]
fn obj_round_trips_through_tobj() {
    let f = field(SPHERE);
    let mesh = polygonise(&f, &params(-1.5, 1.5, 5e-2)).unwrap();
    let mut bytes = Vec::new();
    write_obj(&mesh, &mut bytes).unwrap();
    assert_eq!(bytes.len(), obj_bytes(&mesh));
    let text = String::from_utf8(bytes.clone()).unwrap();
    assert!(text
        .lines()
        .all(|l| l.starts_with("v ") || l.starts_with("f ")));
    let (models, _) = tobj::load_obj_buf(
        &mut std::io::Cursor::new(bytes),
        &tobj::LoadOptions::default(),
        |_| Ok((Vec::new(), Default::default())),
    )
    .unwrap();
    // tobj renumbers vertices in order of first use: compare corner by corner.
    let m = &models[0].mesh;
    assert_eq!(m.positions.len(), 3 * mesh.positions.len());
    assert_eq!(m.indices.len(), 3 * mesh.triangles.len());
    for (c, &i) in mesh.triangles.iter().flatten().enumerate() {
        let (p, j) = (mesh.positions[i as usize], m.indices[c] as usize);
        for (k, &pk) in p.iter().enumerate() {
            let read = m.positions[3 * j + k] as f64;
            // tobj reads f32 (unless its f64 feature is on): compare at f32 precision.
            assert!(
                (read - pk).abs() <= 1e-6 * pk.abs().max(1e-3),
                "{read} vs {pk}"
            );
        }
    }
    // The text itself: 9 significant digits, so within half a unit of the 9th digit.
    let vs: Vec<&str> = text.lines().filter(|l| l.starts_with("v ")).collect();
    for (line, p) in vs.iter().zip(&mesh.positions) {
        for (word, &pk) in line.split(' ').skip(1).zip(p) {
            let digits = word
                .split('e')
                .next()
                .unwrap()
                .chars()
                .filter(char::is_ascii_digit);
            let sig = digits.skip_while(|&c| c == '0').count();
            assert!(sig <= 9, "{word}");
            let read: f64 = word.parse().unwrap();
            assert!((read - pk).abs() <= 5e-9 * pk.abs(), "{word} vs {pk}");
        }
    }
}

#[test]
fn bad_knobs_are_rejected() {
    let f = field(SPHERE);
    let knob = |p: MeshParams| match polygonise(&f, &p) {
        Err(relume::Error::Knob { message }) => message,
        other => panic!("{p:?}: expected a knob error, got {other:?}"),
    };
    for tol in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
        assert!(knob(params(-1.5, 1.5, tol)).contains("tolerance"));
    }
    for (lo, hi) in [
        (1.0, 1.0),
        (1.0, -1.0),
        (f64::NEG_INFINITY, 1.0),
        (-1.0, f64::NAN),
    ] {
        assert!(knob(params(lo, hi, 1e-2)).contains("box"));
    }
    // A unit sphere at 1e-9: spacing ~3.6e-5 over a 3-unit box is ~5·10^14 cells.
    assert!(knob(params(-1.5, 1.5, 1e-9)).contains("2^31"));
}

/// Numbers for reports: `cargo test --test library freeform_mesh:: -- --ignored --nocapture`.
#[test]
#[ignore]
fn report_scene_errors() {
    let cases: [(&str, [f64; 3], [f64; 3]); 2] = [
        ("blobs-128.ron", [-2.2; 3], [2.2; 3]),
        ("csg-holes.ron", [-1.6, -1.2, -1.6], [1.6, 1.6, 1.6]),
    ];
    for (name, lo, hi) in cases {
        let f = scene_field(name);
        for tol in [0.05, 0.02, 0.01, 0.005] {
            let t0 = Instant::now();
            let (mesh, s) = polygonise_with_stats(
                &f,
                &MeshParams {
                    lo,
                    hi,
                    tolerance: tol,
                },
            )
            .unwrap();
            let secs = t0.elapsed().as_secs_f64();
            let h = hausdorff_to_surface(&f, &mesh, 6);
            let c = coverage_distance(&f, &mesh, lo, hi, 24);
            eprintln!(
                "{name} tol {tol}: {} tris, {} OBJ bytes, {secs:.2} s, h {:.4} κ {:.2} \
                 passes {}, mesh→surface {h:.4}, surface→mesh {c:.4}",
                mesh.triangles.len(),
                obj_bytes(&mesh),
                s.spacing,
                s.curvature,
                s.passes
            );
        }
    }
}
