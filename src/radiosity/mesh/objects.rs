//! Light per scene object: the mean irradiance over each object's surface from per-patch
//! exitance, two ways — through the per-corner interpolation on the display mesh (what the
//! player shows, `radiosity::mesh::display`) and straight from the patches each triangle's visible
//! area went into (the radiosity solution itself). This is the quantity a path tracer's irradiance meter measures
//! on the same object, so it is how bakes are compared with Mitsuba (`tests/radiosity/rooms.rs`)
//! and how the study reports per-object error.
//!
//! The radiosity solution's irradiance at patch p is H_p = B_p / ρ_p (B the reflected exitance,
//! ρ_p the patch's albedo, the area-weighted mean of its pieces'; a channel with ρ_p = 0 reports
//! 0). Dividing by the patch's albedo rather than the triangle's matters where a patch mixes
//! materials (a floor patch that also holds part of a grey threshold reflects with the mixed
//! albedo: dividing its B by the floor's own blue albedo overstated the floor's blue irradiance
//! by up to 1.7x on the door-ajar scene). H is averaged over each object by area.

use crate::radiosity::PatchSet;
use crate::scene::Scene;
use serde::Serialize;

/// One object's light. `irradiance` and `irradiance_patches` are the light arriving from other
/// surfaces (bounced light, and area emitters' light); punctual lights' direct light is
/// `direct`, and `total` = `direct` + `irradiance` is what a path tracer's irradiance meter on
/// the object measures.
#[derive(Clone, Debug, Serialize)]
pub struct ObjectLight {
    pub name: String,
    /// Total triangle area (scene units²).
    pub area: f64,
    /// Mean direct irradiance from the punctual lights, shadowed (0 until
    /// [`ObjectLight::with_direct`] sets it).
    pub direct: [f64; 3],
    /// Mean irradiance from other surfaces (the indirect part): the corner interpolation on
    /// the display mesh, per channel.
    pub irradiance: [f64; 3],
    /// `direct` + `irradiance`.
    pub total: [f64; 3],
    /// Mean irradiance from the patches (area-weighted over each triangle's visible pieces).
    pub irradiance_patches: [f64; 3],
    /// Largest patch irradiance touching the object (0 exactly when no light reaches it).
    pub max_patch_irradiance: f64,
}

/// Per-object light of `scene` from per-patch reflected exitance `b` (`[n][3]`, e.g. `S·E`).
/// `set` must be the voxelization of `scene`.
pub fn object_light(scene: &Scene, set: &PatchSet, b: &[[f32; 3]]) -> Vec<ObjectLight> {
    let mut out: Vec<ObjectLight> = scene
        .objects
        .iter()
        .map(|name| ObjectLight {
            name: name.clone(),
            area: 0.0,
            direct: [0.0; 3],
            irradiance: [0.0; 3],
            total: [0.0; 3],
            irradiance_patches: [0.0; 3],
            max_patch_irradiance: 0.0,
        })
        .collect();
    let h: Vec<[f64; 3]> = set
        .patches
        .iter()
        .zip(b)
        .map(|(p, b)| {
            std::array::from_fn(|c| {
                if p.albedo[c] > 0.0 {
                    b[c] as f64 / p.albedo[c] as f64
                } else {
                    0.0
                }
            })
        })
        .collect();
    // Through the corners of the mesh the player draws (radiosity::mesh::display).
    let (display, lists) = crate::radiosity::mesh::display::display_mesh_of(scene, set);
    for t in 0..display.triangles.len() {
        let o = &mut out[display.triangle_object[t] as usize];
        let area = display.triangle_area(t) as f64;
        o.area += area;
        for k in 0..3 {
            let (ps, ws) = lists.list(3 * t + k);
            for (&p, &w) in ps.iter().zip(ws) {
                for (acc, hc) in o.irradiance.iter_mut().zip(h[p as usize]) {
                    *acc += area / 3.0 * w as f64 * hc;
                }
            }
        }
    }
    // Straight from the patches each scene triangle's visible area went into.
    let mut visible_area = vec![0.0f64; out.len()];
    for t in 0..scene.triangles.len() {
        let o = &mut out[scene.triangle_object[t] as usize];
        let (ps, areas) = set.triangle_patches.list(t);
        for (&p, &a) in ps.iter().zip(areas) {
            for (acc, hc) in o.irradiance_patches.iter_mut().zip(h[p as usize]) {
                *acc += a as f64 * hc;
                o.max_patch_irradiance = o.max_patch_irradiance.max(hc);
            }
            visible_area[scene.triangle_object[t] as usize] += a as f64;
        }
    }
    for (o, &va) in out.iter_mut().zip(&visible_area) {
        for c in 0..3 {
            o.irradiance[c] /= o.area.max(f64::MIN_POSITIVE);
            o.irradiance_patches[c] /= va.max(f64::MIN_POSITIVE);
        }
        o.total = o.irradiance;
    }
    out
}

impl ObjectLight {
    /// Set the direct part (and the total) from a mean direct irradiance.
    pub fn with_direct(mut self, direct: [f64; 3]) -> Self {
        self.direct = direct;
        self.total = std::array::from_fn(|c| direct[c] + self.irradiance[c]);
        self
    }
}
