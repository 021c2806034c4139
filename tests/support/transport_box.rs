//! A realistic transport matrix for compression tests and benches (not part of the product):
//! a closed unit box whose six walls are split into k×k patches (n = 6k²), Cornell-like albedos
//! (red left wall, green right wall, white elsewhere), point-to-disc form factors between patches
//! of different walls (`cosθ_i cosθ_j A_j / (π r² + A_j)`, no occlusion: a box is convex), rows
//! normalised to 1 (closed scene), patches in a seeded random order (as a voxelizer would leave
//! them), and `S_k = Σ_{h=1..k} M^h` or `S_∞ = (I − M)⁻¹ M` with `M = diag(ρ_c) F` (faer).
//!
//! To use the real Cornell box instead, set `RELUME_TRANSPORT_NPY=path/to/transport.npy`:
//! [`transport_or_env`] then reads it with `relume::baked::read_npy_f32`.
#![allow(dead_code, clippy::needless_range_loop)]

use relume::radiosity::TransportMatrix;

/// Patch geometry of the box.
pub struct BoxScene {
    pub n: usize,
    pub centre: Vec<[f32; 3]>,
    pub normal: Vec<[f32; 3]>,
    pub area: Vec<f32>,
    pub albedo: Vec<[f32; 3]>,
}

const WHITE: [f32; 3] = [0.73, 0.73, 0.73];
const RED: [f32; 3] = [0.63, 0.065, 0.05];
const GREEN: [f32; 3] = [0.14, 0.45, 0.09];

/// The box with k×k patches per wall, patches shuffled by `seed`.
pub fn closed_box(k: usize, seed: u64) -> BoxScene {
    let mut patches = Vec::new();
    // (axis, side, normal sign, albedo)
    let walls: [(usize, f32, f32, [f32; 3]); 6] = [
        (1, 0.0, 1.0, WHITE),  // floor
        (1, 1.0, -1.0, WHITE), // ceiling
        (0, 0.0, 1.0, RED),    // left
        (0, 1.0, -1.0, GREEN), // right
        (2, 0.0, 1.0, WHITE),  // back
        (2, 1.0, -1.0, WHITE), // front
    ];
    let h = 1.0 / k as f32;
    for (axis, side, sign, albedo) in walls {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for a in 0..k {
            for b in 0..k {
                let mut c = [0.0f32; 3];
                c[axis] = side;
                c[u] = (a as f32 + 0.5) * h;
                c[v] = (b as f32 + 0.5) * h;
                let mut nrm = [0.0f32; 3];
                nrm[axis] = sign;
                patches.push((c, nrm, h * h, albedo));
            }
        }
    }
    // Seeded Fisher–Yates shuffle (splitmix64).
    let mut state = seed;
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    for i in (1..patches.len()).rev() {
        let j = (next() % (i as u64 + 1)) as usize;
        patches.swap(i, j);
    }
    BoxScene {
        n: patches.len(),
        centre: patches.iter().map(|p| p.0).collect(),
        normal: patches.iter().map(|p| p.1).collect(),
        area: patches.iter().map(|p| p.2).collect(),
        albedo: patches.iter().map(|p| p.3).collect(),
    }
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Point-to-disc form factors, rows normalised to sum to 1. Row-major n×n.
pub fn form_factors(s: &BoxScene) -> Vec<f32> {
    let n = s.n;
    let mut f = vec![0.0f32; n * n];
    for i in 0..n {
        let row = &mut f[i * n..(i + 1) * n];
        let mut sum = 0.0f64;
        for j in 0..n {
            if i == j {
                continue;
            }
            let d = sub(s.centre[j], s.centre[i]);
            let r2 = dot(d, d);
            let r = r2.sqrt();
            let ci = dot(s.normal[i], d) / r;
            let cj = -dot(s.normal[j], d) / r;
            if ci > 0.0 && cj > 0.0 {
                let v = ci * cj * s.area[j] / (std::f32::consts::PI * r2 + s.area[j]);
                row[j] = v;
                sum += v as f64;
            }
        }
        for v in row.iter_mut() {
            *v = (*v as f64 / sum) as f32;
        }
    }
    f
}

/// `S_k` (`bounces = Some(k)`) or `S_∞` (`None`) for the box, 3 channels.
pub fn transport(s: &BoxScene, bounces: Option<usize>) -> TransportMatrix {
    use faer::linalg::solvers::Solve;
    use faer::Mat;
    let n = s.n;
    let f = form_factors(s);
    let mut data = Vec::with_capacity(3 * n * n);
    for c in 0..3 {
        let m = Mat::<f32>::from_fn(n, n, |i, j| s.albedo[i][c] * f[i * n + j]);
        let out: Mat<f32> = match bounces {
            Some(k) => {
                // Horner: S = M (I + M (I + ... )).
                let mut acc = m.clone();
                for _ in 1..k {
                    let t = &m * &acc;
                    acc = &m + &t;
                }
                acc
            }
            None => {
                let a =
                    Mat::<f32>::from_fn(n, n, |i, j| (if i == j { 1.0 } else { 0.0 }) - m[(i, j)]);
                a.partial_piv_lu().solve(&m)
            }
        };
        for i in 0..n {
            for j in 0..n {
                data.push(out[(i, j)].max(0.0));
            }
        }
    }
    TransportMatrix::new(3, n, data).unwrap()
}

/// The box's transport, cached under `target/relume-test-cache/` (building the n ≈ 4096 one
/// takes a while), or the matrix named by `RELUME_TRANSPORT_NPY` when that is set.
pub fn transport_or_env(k: usize, bounces: Option<usize>) -> TransportMatrix {
    if let Ok(p) = std::env::var("RELUME_TRANSPORT_NPY") {
        return relume::baked::transport::read_file(std::path::Path::new(&p))
            .expect("RELUME_TRANSPORT_NPY");
    }
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/relume-test-cache");
    let name = format!(
        "box_k{k}_{}.npy",
        bounces.map(|b| b.to_string()).unwrap_or("inf".into())
    );
    let path = dir.join(name);
    if let Ok(m) = relume::baked::transport::read_file(&path) {
        return m;
    }
    let m = transport(&closed_box(k, 7), bounces);
    let _ = std::fs::create_dir_all(&dir);
    let tmp = path.with_extension(format!("tmp{}", std::process::id()));
    if relume::baked::transport::write_file(&tmp, &m).is_ok() {
        let _ = std::fs::rename(&tmp, &path);
    }
    m
}

/// Geometric light configurations `[3][n]`: direct exitance `E = ρ · irradiance` from
/// - `ceiling`: a point light just below the ceiling's centre (dense, smooth);
/// - `corner`: a point light near a lower corner (strongly graded);
/// - `spot`: a narrow cone from the ceiling onto the floor (about 5 % of the patches lit).
pub fn box_lights(s: &BoxScene) -> Vec<(String, Vec<f32>)> {
    let n = s.n;
    let light = |pos: [f32; 3], cone: Option<([f32; 3], f32)>| -> Vec<f32> {
        let mut e = vec![0.0f32; 3 * n];
        for i in 0..n {
            let d = sub(pos, s.centre[i]);
            let r2 = dot(d, d);
            let cos = dot(s.normal[i], d) / r2.sqrt();
            if cos <= 0.0 {
                continue;
            }
            if let Some((axis, cos_max)) = cone {
                let to = sub(s.centre[i], pos);
                if dot(to, axis) / r2.sqrt() < cos_max {
                    continue;
                }
            }
            let irr = cos / r2;
            for c in 0..3 {
                e[c * n + i] = s.albedo[i][c] * irr;
            }
        }
        e
    };
    vec![
        ("ceiling".into(), light([0.5, 0.95, 0.5], None)),
        ("corner".into(), light([0.1, 0.1, 0.9], None)),
        (
            "spot".into(),
            light([0.5, 0.99, 0.5], Some(([0.0, -1.0, 0.0], 0.95))),
        ),
    ]
}
