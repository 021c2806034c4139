//! CPU twins of the per-frame radiosity kernels: direct exitance per patch
//! (`shaders/direct_light.wgsl`) and the dense gather B = S·E (`shaders/gather_dense.wgsl`).
//! Both sum in the same order and precision (f32) as the kernels.

use super::lights::{light_irradiance, GpuLight};
use super::mesh_reference::FrameSettings;
use crate::radiosity::PatchSet;
use glam::Vec3;

/// Direct exitance E of every patch: albedo × mean irradiance over the patch's sample points
/// (each light's contribution gated by `visible(light, point, normal, to_light, distance)` when shadows
/// are on) plus π·L·`emission_scale` for emitters.
pub fn patch_exitance(
    set: &PatchSet,
    lights: &[GpuLight],
    s: &FrameSettings,
    visible: &(dyn Fn(usize, Vec3, Vec3, Vec3, f32) -> bool + Sync),
) -> Vec<[f32; 3]> {
    use rayon::prelude::*;
    let spp = set.samples_per_patch as usize;
    set.patches
        .par_iter()
        .enumerate()
        .map(|(i, patch)| {
            let mut e = Vec3::ZERO;
            if s.direct && spp > 0 {
                let mut h = Vec3::ZERO;
                for sp in &set.samples[i * spp..(i + 1) * spp] {
                    let (p, n) = (Vec3::from(sp.position), Vec3::from(sp.normal));
                    for (l, light) in lights.iter().enumerate() {
                        let (irr, to_light, dist) = light_irradiance(light, p, n);
                        if irr.max_element() > 0.0
                            && (!s.shadows || visible(l, p, n, to_light, dist))
                        {
                            h += irr;
                        }
                    }
                }
                e = Vec3::from(patch.albedo) * h / spp as f32;
            }
            if s.emission {
                e += std::f32::consts::PI * Vec3::from(patch.emission) * s.emission_scale;
            }
            e.to_array()
        })
        .collect()
}

/// B = S·E per channel from a dense `[channels, n, n]` matrix (channels 1 = grey: the same
/// matrix for R, G and B).
pub fn gather_dense(matrix: &[f32], channels: usize, n: usize, e: &[[f32; 3]]) -> Vec<[f32; 3]> {
    use rayon::prelude::*;
    assert_eq!(matrix.len(), channels * n * n);
    (0..n)
        .into_par_iter()
        .map(|i| {
            let mut b = [0.0f32; 3];
            for (c, bc) in b.iter_mut().enumerate() {
                let m = &matrix[(c.min(channels - 1) * n + i) * n..][..n];
                let mut sum = 0.0f32;
                for j in 0..n {
                    sum += m[j] * e[j][c];
                }
                *bc = sum;
            }
            b
        })
        .collect()
}

/// Per-corner indirect exitance (3 floats per corner) from per-patch values: the twin of
/// `shaders/corner_interpolate.wgsl`.
pub fn corner_indirect(set: &PatchSet, b: &[[f32; 3]]) -> Vec<f32> {
    let lists = &set.corners;
    let mut out = Vec::with_capacity(lists.len() * 3);
    for k in 0..lists.len() {
        let (p, w) = lists.list(k);
        let mut acc = Vec3::ZERO;
        for (&j, &w) in p.iter().zip(w) {
            acc += w * Vec3::from(b[j as usize]);
        }
        out.extend_from_slice(&acc.to_array());
    }
    out
}

/// Points per object [`object_direct`] averages over: the standard error of a half-shadowed
/// object's mean is then about 0.5/√4096 ≈ 0.8 % of its sunlit irradiance.
pub const OBJECT_DIRECT_POINTS: usize = 4096;

/// Mean direct irradiance (W·m⁻² per channel) from punctual `lights` over each object of `scene`:
/// [`OBJECT_DIRECT_POINTS`] points per object, uniform over its area (stratified along the
/// object's cumulative triangle area, seeded per object), each lit on its front face as the
/// player shades it — `light_irradiance` gated by `visible` (shadow rays). What a path tracer's
/// irradiance meter on the object measures of the punctual lights alone.
pub fn object_direct(
    scene: &crate::scene::Scene,
    lights: &[GpuLight],
    visible: &(dyn Fn(usize, Vec3, Vec3, Vec3, f32) -> bool + Sync),
) -> Vec<[f64; 3]> {
    use rayon::prelude::*;
    let mut tris: Vec<Vec<usize>> = vec![Vec::new(); scene.objects.len()];
    for t in 0..scene.triangles.len() {
        if !scene.is_degenerate(t) {
            tris[scene.triangle_object[t] as usize].push(t);
        }
    }
    tris.par_iter()
        .enumerate()
        .map(|(o, ts)| {
            let mut cdf = Vec::with_capacity(ts.len());
            let mut total = 0.0f64;
            for &t in ts {
                total += scene.triangle_area(t) as f64;
                cdf.push(total);
            }
            if total <= 0.0 {
                return [0.0; 3];
            }
            let mut rng = crate::radiosity::geometry::item_rng(0x0b1e_c7d1, o as u64, 0);
            let mut sum = glam::DVec3::ZERO;
            for u in rng.strata(OBJECT_DIRECT_POINTS) {
                let k = cdf.partition_point(|&c| c <= u * total).min(ts.len() - 1);
                let [a, b, c] = scene.corners(ts[k]);
                let (r1, r2) = (rng.f64().sqrt() as f32, rng.f64() as f32);
                let p = a * (1.0 - r1) + b * (r1 * (1.0 - r2)) + c * (r1 * r2);
                let n = (b - a).cross(c - a).normalize();
                for (l, light) in lights.iter().enumerate() {
                    let (irr, to_light, dist) = light_irradiance(light, p, n);
                    if irr.max_element() > 0.0 && visible(l, p, n, to_light, dist) {
                        sum += irr.as_dvec3();
                    }
                }
            }
            (sum / OBJECT_DIRECT_POINTS as f64).to_array()
        })
        .collect()
}
