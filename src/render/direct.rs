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
