//! Twin tests of `lighting.wgsl` on the GPU through a compute harness that includes it:
//! `light_irradiance` (point, spot, directional), `point_face` (ties included) and the shadow
//! layers' projections, against their Rust twins. Tolerances are stated with the measured error.

use crate::common;
use crate::twins;

use common::gpu;
use glam::{Mat4, Vec3, Vec4};
use rand_core::RngCore;
use relume::gpu::{compute, readback};
use relume::render::lights::{
    light_irradiance, point_face, shadow_projections, GpuLight, KIND_DIRECTIONAL, KIND_POINT,
    KIND_SPOT,
};
use relume::scene::LightKind;
use twins::*;

// 3. lighting.wgsl: light_irradiance, point_face, the shadow layers' projections

fn random_light(r: &mut Rng) -> GpuLight {
    let kind = match r.next_u32() % 3 {
        0 => LightKind::Directional,
        1 => LightKind::Point,
        _ => {
            let inner = uniform(r, 0.0, 1.0);
            // A quarter of the spots have equal cones (a hard step).
            let outer = if r.next_u32().is_multiple_of(4) {
                inner
            } else {
                inner + uniform(r, 0.02, 0.5)
            };
            LightKind::Spot {
                inner_cone: inner,
                outer_cone: outer,
            }
        }
    };
    let mut l = light(
        kind,
        Vec3::new(
            uniform(r, -2.0, 2.0),
            uniform(r, -2.0, 2.0),
            uniform(r, -2.0, 2.0),
        ),
        unit(r),
        Vec3::new(
            uniform(r, 0.0, 3.0),
            uniform(r, 0.0, 3.0),
            uniform(r, 0.0, 3.0),
        ),
        uniform(r, 0.1, 4.0),
    );
    if r.next_u32().is_multiple_of(2) {
        l.range = Some(uniform(r, 0.5, 5.0));
    }
    GpuLight::from_light(&l, 1.0, 0)
}

#[test]
fn light_irradiance_matches_its_rust_twin() {
    let Some(gpu) = gpu() else { return };
    let mut r = rng(3);
    let lights: Vec<GpuLight> = (0..64).map(|_| random_light(&mut r)).collect();
    let cases = 8192usize;
    let mut input: Vec<[f32; 4]> = Vec::with_capacity(2 * cases);
    for i in 0..cases {
        let li = i % lights.len();
        let l = &lights[li];
        let (pos, dir) = (
            Vec3::from_slice(&l.position[..3]),
            Vec3::from_slice(&l.direction[..3]),
        );
        let p = if l.kind() == KIND_SPOT && i % 4 != 3 {
            // Most spot cases inside or just outside the outer cone, through the smoothstep.
            let outer = f32::from_bits(l.params[3]).acos();
            let a = uniform(&mut r, 0.0, 1.2 * outer);
            let perp = dir.cross(unit(&mut r)).normalize();
            pos + (dir * a.cos() + perp * a.sin()) * uniform(&mut r, 0.05, 4.0)
        } else {
            Vec3::new(
                uniform(&mut r, -2.5, 2.5),
                uniform(&mut r, -2.5, 2.5),
                uniform(&mut r, -2.5, 2.5),
            )
        };
        // Half the normals face the light (so that most values are not zero).
        let mut n = unit(&mut r);
        let to_light = if l.kind() == KIND_DIRECTIONAL {
            -dir
        } else {
            pos - p
        };
        if i % 2 == 0 && n.dot(to_light) < 0.0 {
            n = -n;
        }
        input.push(p.extend(li as f32).to_array());
        input.push(n.extend(0.0).to_array());
    }
    let p = lighting_harness(
        &gpu,
        r#"
@group(0) @binding(0) var<storage, read> test_lights: array<GpuLight>;
@group(0) @binding(1) var<storage, read> test_in: array<vec4<f32>>;        // p (w = light), n
@group(0) @binding(2) var<storage, read_write> test_out: array<vec4<f32>>; // irradiance, to_light
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= arrayLength(&test_in) / 2u) {
        return;
    }
    let p = test_in[2u * i];
    let inc = light_irradiance(test_lights[u32(p.w)], p.xyz, test_in[2u * i + 1u].xyz);
    test_out[2u * i] = vec4<f32>(inc.irradiance, 0.0);
    test_out[2u * i + 1u] = vec4<f32>(inc.to_light, 0.0);
}
"#,
    );
    let lb = compute::storage(&gpu, "lights", &lights);
    let ib = compute::storage(&gpu, "in", &input);
    let ob = compute::output(&gpu, "out", input.len() as u64 * 16);
    let g = compute::bind(
        &gpu,
        &p,
        &[
            lb.as_entire_binding(),
            ib.as_entire_binding(),
            ob.as_entire_binding(),
        ],
    );
    dispatch(&gpu, &p, &[&g], cases as u32);
    let got = readback::read_f32(&gpu, &ob).unwrap();
    let (mut max_h, mut max_l, mut nonzero) = (0.0f32, 0.0f32, [0usize; 3]);
    let mut worst = String::new();
    let mut results = Vec::with_capacity(cases);
    for i in 0..cases {
        let l = &lights[i % lights.len()];
        let (p, n) = (
            Vec3::from_slice(&input[2 * i][..3]),
            Vec3::from_slice(&input[2 * i + 1][..3]),
        );
        let (h, to_light, d) = light_irradiance(l, p, n);
        let gh = Vec3::from_slice(&got[8 * i..8 * i + 3]);
        let gl = Vec3::from_slice(&got[8 * i + 4..8 * i + 7]);
        // Error relative to the light's unwindowed, unattenuated irradiance scale at p (the
        // range window and the spot's smoothstep cancel digits near their edges).
        let rad = Vec3::from_slice(&l.radiance[..3]).max_element();
        let scale = if l.kind() == KIND_DIRECTIONAL {
            rad
        } else {
            rad / (d * d).max(1e-12)
        }
        .max(f32::MIN_POSITIVE);
        let eh = (gh - h).abs().max_element() / scale;
        let el = (gl - to_light).abs().max_element();
        if eh > max_h {
            max_h = eh;
            worst = format!("case {i} kind {} gpu {gh} cpu {h}", l.kind());
        }
        max_l = max_l.max(el);
        if h.max_element() > 0.0 {
            nonzero[l.kind() as usize] += 1;
        }
        results.push((i, eh, el, gh, h));
    }
    eprintln!(
        "light_irradiance: max relative error {max_h:.3e} ({worst}), to_light max |error| {max_l:.3e}; lit cases per kind {nonzero:?}"
    );
    // Measured on lavapipe: irradiance 1.4e-7 relative, tolerance 5e-7 (3.5x); to_light is
    // bit-identical there (0), tolerance two ulp of a unit vector (2.4e-7) for GPUs whose
    // sqrt and division are not correctly rounded.
    const TOL_H: f32 = 5e-7;
    const TOL_L: f32 = 2.4e-7;
    for (i, eh, el, gh, h) in results {
        assert!(
            eh <= TOL_H,
            "case {i}: irradiance gpu {gh} cpu {h} (relative {eh:.3e})"
        );
        assert!(el <= TOL_L, "case {i}: to_light error {el:.3e}");
    }
    for (k, &c) in nonzero.iter().enumerate() {
        assert!(c > 500, "kind {k}: only {c} lit cases");
    }
}

#[test]
fn point_face_matches_its_rust_twin_including_ties() {
    let Some(gpu) = gpu() else { return };
    let mut dirs: Vec<Vec3> = Vec::new();
    // Every axis-aligned, edge and corner direction (ties of two and three axes), zero and
    // negative zeros, scaled ties.
    for x in [-1.0f32, 0.0, 1.0] {
        for y in [-1.0f32, 0.0, 1.0] {
            for z in [-1.0f32, 0.0, 1.0] {
                dirs.push(Vec3::new(x, y, z));
                dirs.push(Vec3::new(x, y, z) * 3.5);
            }
        }
    }
    dirs.extend([
        Vec3::new(-0.0, -0.0, -0.0),
        Vec3::new(-0.0, 0.0, -0.0),
        Vec3::new(-0.0, 1.0, 1.0),
        Vec3::new(2.0, -2.0, 1.0),
        Vec3::new(-3.0, 3.0, 3.0),
        Vec3::new(1e-3, -1e-3, 0.0),
        Vec3::new(0.5, 0.25, -0.5),
        Vec3::new(-0.25, -0.5, 0.5),
    ]);
    let mut r = rng(5);
    for _ in 0..2000 {
        dirs.push(unit(&mut r) * uniform(&mut r, 0.01, 10.0));
        // Ties between two random axes with random signs.
        let a = uniform(&mut r, 0.1, 2.0);
        let b = uniform(&mut r, 0.0, a);
        let s = |r: &mut Rng| {
            if r.next_u32().is_multiple_of(2) {
                1.0
            } else {
                -1.0
            }
        };
        let v = [a * s(&mut r), a * s(&mut r), b * s(&mut r)];
        let k = (r.next_u32() % 3) as usize;
        dirs.push(Vec3::new(v[k], v[(k + 1) % 3], v[(k + 2) % 3]));
    }
    let p = lighting_harness(
        &gpu,
        r#"
@group(0) @binding(0) var<storage, read> test_dirs: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> test_faces: array<u32>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x < arrayLength(&test_dirs)) {
        test_faces[id.x] = point_face(test_dirs[id.x].xyz);
    }
}
"#,
    );
    let input: Vec<[f32; 4]> = dirs.iter().map(|d| d.extend(0.0).to_array()).collect();
    let ib = compute::storage(&gpu, "dirs", &input);
    let ob = compute::output(&gpu, "faces", dirs.len() as u64 * 4);
    let g = compute::bind(&gpu, &p, &[ib.as_entire_binding(), ob.as_entire_binding()]);
    dispatch(&gpu, &p, &[&g], dirs.len() as u32);
    let got: Vec<u32> = bytemuck::cast_slice(&readback::read_buffer(&gpu, &ob).unwrap()).to_vec();
    let mut per_face = [0usize; 6];
    for (i, d) in dirs.iter().enumerate() {
        let want = point_face(*d);
        assert_eq!(got[i], want, "direction {d:?}");
        per_face[want as usize] += 1;
    }
    // Independent of both: a face's axis is (one of) the largest components, with its sign.
    for d in &dirs {
        let f = point_face(*d) as usize;
        let (axis, negative) = (f / 2, f % 2 == 1);
        let a = d.abs();
        assert!(a[axis] >= a.max_element(), "{d:?} → face {f}");
        assert_eq!(d[axis] < 0.0, negative, "{d:?} → face {f}");
    }
    eprintln!(
        "point_face: {} directions agree; per face {per_face:?}",
        dirs.len()
    );
    assert!(per_face.iter().all(|&c| c > 100), "{per_face:?}");
}

#[test]
fn shadow_layer_projections_match_their_rust_twin() {
    let Some(gpu) = gpu() else { return };
    let (centre, radius) = (Vec3::new(0.2, 0.5, -0.1), 1.7);
    let lights = [
        GpuLight::from_light(
            &light(
                LightKind::Directional,
                Vec3::ZERO,
                Vec3::new(0.4, -1.0, 0.3),
                Vec3::ONE,
                1.0,
            ),
            1.0,
            0,
        ),
        GpuLight::from_light(
            &light(
                LightKind::Spot {
                    inner_cone: 0.2,
                    outer_cone: 0.6,
                },
                Vec3::new(-1.0, 2.5, 0.5),
                Vec3::new(0.5, -1.0, -0.2),
                Vec3::ONE,
                1.0,
            ),
            1.0,
            0,
        ),
        GpuLight::from_light(
            &light(
                LightKind::Point,
                Vec3::new(0.3, 0.6, 0.1),
                Vec3::Y,
                Vec3::ONE,
                1.0,
            ),
            1.0,
            0,
        ),
        // A directional light straight down (the other `up` vector).
        GpuLight::from_light(
            &light(
                LightKind::Directional,
                Vec3::ZERO,
                Vec3::NEG_Y,
                Vec3::ONE,
                1.0,
            ),
            1.0,
            0,
        ),
    ];
    let u = lights_uniform(&lights, centre, radius);
    let mut r = rng(9);
    let cases = 4096usize;
    let points: Vec<[f32; 4]> = (0..cases)
        .map(|i| {
            let p = centre + unit(&mut r) * radius * uniform(&mut r, 0.0, 1.0).cbrt();
            p.extend((i % lights.len()) as f32).to_array()
        })
        .collect();
    // The layer choice and projection of `shadow_visibility`, without the normal offset and
    // the texture lookup.
    let p = lighting_harness(
        &gpu,
        r#"
@group(0) @binding(0) var<storage, read> test_points: array<vec4<f32>>;   // p, w = light
@group(0) @binding(1) var<storage, read_write> test_clip: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> test_layer: array<u32>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= arrayLength(&test_points)) {
        return;
    }
    let p = test_points[i];
    let light = lights.lights[u32(p.w)];
    var layer = light.params.y;
    if (light.params.x == KIND_POINT) {
        layer = layer + point_face(p.xyz - light.position.xyz);
    }
    test_layer[i] = layer;
    test_clip[i] = lights.layer_view_proj[layer] * vec4<f32>(p.xyz, 1.0);
}
"#,
    );
    let ub = compute::uniform(&gpu, "lights", &u);
    let pb = compute::storage(&gpu, "points", &points);
    let cb = compute::output(&gpu, "clip", cases as u64 * 16);
    let lb = compute::output(&gpu, "layer", cases as u64 * 4);
    let g0 = compute::bind(
        &gpu,
        &p,
        &[
            pb.as_entire_binding(),
            cb.as_entire_binding(),
            lb.as_entire_binding(),
        ],
    );
    let g1 = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &p.get_bind_group_layout(1),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: ub.as_entire_binding(),
        }],
    });
    dispatch(&gpu, &p, &[&g0, &g1], cases as u32);
    let clip = readback::read_f32(&gpu, &cb).unwrap();
    let layers: Vec<u32> =
        bytemuck::cast_slice(&readback::read_buffer(&gpu, &lb).unwrap()).to_vec();
    let projections: Vec<Vec<Mat4>> = lights
        .iter()
        .map(|l| shadow_projections(l, centre, radius))
        .collect();
    let mut max_err = 0.0f32;
    let mut inside_cone = 0;
    for i in 0..cases {
        let li = i % lights.len();
        let l = &u.lights[li];
        let pos = Vec3::from_slice(&points[i][..3]);
        let face = if l.kind() == KIND_POINT {
            point_face(pos - Vec3::from_slice(&l.position[..3]))
        } else {
            0
        };
        assert_eq!(layers[i], l.params[1] + face, "point {i}: layer");
        let want = projections[li][face as usize] * pos.extend(1.0);
        let got = Vec4::from_slice(&clip[4 * i..4 * i + 4]);
        let e = (got - want).abs().max_element() / want.abs().max_element().max(1.0);
        max_err = max_err.max(e);
        // Measured on lavapipe: 2.3e-7 relative (a chain of four multiply-adds): 2x.
        assert!(
            e <= 4.8e-7,
            "point {i}: gpu {got} cpu {want} (relative {e:.3e})"
        );
        // Independent property of the twin: the chosen layer sees the point (inside the
        // layer's frustum) — for directional and point lights every point of the sphere, for
        // the spot every point inside its outer cone.
        let ndc = want.truncate() / want.w;
        let cone = (pos - Vec3::from_slice(&l.position[..3]))
            .normalize()
            .dot(Vec3::from_slice(&l.direction[..3]));
        let must_see = l.kind() != KIND_SPOT || cone > f32::from_bits(l.params[3]);
        inside_cone += (l.kind() == KIND_SPOT && must_see) as usize;
        if must_see {
            let eps = 1e-4;
            assert!(
                want.w > 0.0
                    && ndc.x.abs() <= 1.0 + eps
                    && ndc.y.abs() <= 1.0 + eps
                    && (-eps..=1.0 + eps).contains(&ndc.z),
                "light {li} face {face}: point {pos} projects to {ndc} (w {})",
                want.w
            );
        }
    }
    eprintln!("shadow projections: max relative clip error {max_err:.3e}; {inside_cone} points inside the spot's cone");
    assert!(inside_cone > 50);
}

// ---------------------------------------------------------------------------------------------
