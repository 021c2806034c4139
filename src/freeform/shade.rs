//! From hits to a frame: normal from the field's gradient, Lambert and Phong with the sun, sun
//! shadows by casting toward the sun through the same field (by the frame's own method).

use super::field::{dot, Field};
use super::reference;
use super::rmlrc::{self, CastStats, RmlrcParams};
use super::view::View;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How primary and shadow rays are cast.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Method {
    /// The exact per-ray reference (certified root isolation).
    Reference,
    /// Recursive multilevel ray casting with its knobs.
    Rmlrc(RmlrcParams),
}

/// Lighting of a frame: unit vector toward the sun (y up), the sun's colour on surfaces (white,
/// or reddened by the air), ambient fraction, background.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    pub sun: [f64; 3],
    pub sun_colour: [f64; 3],
    pub ambient: f64,
    pub background: [f64; 3],
    pub shadows: bool,
}

/// The unit vector toward a sun at `azimuth` (clockwise from north = −z) and `elevation`, in
/// the y-up scene frame: `(sin az·cos el, sin el, −cos az·cos el)`.
pub fn sun_direction(azimuth_deg: f64, elevation_deg: f64) -> [f64; 3] {
    let (sa, ca) = azimuth_deg.to_radians().sin_cos();
    let (se, ce) = elevation_deg.to_radians().sin_cos();
    [sa * ce, se, -ca * ce]
}

/// A rendered frame: linear RGB, distance along each pixel's unit ray (`+inf` where it misses),
/// unit normals (0 where it misses), and the caster's counts.
#[derive(Clone, Debug)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<[f32; 3]>,
    pub depth: Vec<f64>,
    pub normals: Vec<[f32; 3]>,
    pub stats: CastStats,
}

impl Frame {
    /// Pixels whose ray hits a surface.
    pub fn hits(&self) -> usize {
        self.depth.iter().filter(|d| d.is_finite()).count()
    }
}

/// The distance along each pixel's unit ray to the first surface point, by `method`.
pub fn primary(field: &Field, view: &View, method: &Method) -> (Vec<Option<f64>>, CastStats) {
    match method {
        Method::Reference => {
            let (w, h) = (view.width as usize, view.height as usize);
            let hits = (0..w * h)
                .into_par_iter()
                .map(|i| {
                    let (dir, len) = view.pixel_ray((i % w) as u32, (i / w) as u32);
                    reference::first_hit(field, view.eye, dir, view.near * len, view.far * len)
                        .map(|h| h.t)
                })
                .collect();
            (hits, CastStats::default())
        }
        Method::Rmlrc(p) => rmlrc::cast(field, view, p),
    }
}

/// Render a frame: primary rays, normals, shading and sun shadows.
pub fn render(field: &Field, view: &View, method: &Method, light: &Lighting) -> Frame {
    render_with(field, view, method, light, None)
}

/// The albedo of a hit from the unit ray and the distance along it, in place of the surface's
/// colour (a scene's thematic textures).
pub type Albedo<'a> = &'a (dyn Fn([f64; 3], f64) -> [f64; 3] + Sync);

/// [`render`] with every surface's colour replaced by `albedo` when given.
pub fn render_with(
    field: &Field,
    view: &View,
    method: &Method,
    light: &Lighting,
    albedo: Option<Albedo>,
) -> Frame {
    let (hits, stats) = primary(field, view, method);
    let w = view.width as usize;
    let scale = ((view.far * view.near).sqrt()).max(1e-12);
    let shaded: Vec<([f32; 3], [f32; 3])> = hits
        .par_iter()
        .enumerate()
        .map(|(i, hit)| {
            let Some(t) = *hit else {
                return (light.background.map(|v| v as f32), [0.0; 3]);
            };
            let (dir, _) = view.pixel_ray((i % w) as u32, (i / w) as u32);
            let p: [f64; 3] = std::array::from_fn(|k| view.eye[k] + t * dir[k]);
            let mut n = field.normal(p);
            if dot(n, dir) > 0.0 {
                n = n.map(|v| -v);
            }
            let (_, leaf, _) = field.eval_with_leaf(p);
            let leaf = &field.leaves[leaf];
            let l = light.sun;
            let ndl = dot(n, l).max(0.0);
            let lit =
                ndl > 0.0 && !(light.shadows && in_shadow(field, view, method, p, n, l, t, scale));
            let vis = if lit { 1.0 } else { 0.0 };
            let refl: [f64; 3] = std::array::from_fn(|k| 2.0 * dot(n, l) * n[k] - l[k]);
            let spec = leaf.specular * vis * (-dot(refl, dir)).max(0.0).powi(32);
            let a = light.ambient;
            let color = albedo.map_or(leaf.color, |f| f(dir, t));
            let c = light.sun_colour;
            let rgb = std::array::from_fn(|k| {
                (color[k] * (a + (1.0 - a) * ndl * vis * c[k]) + spec * c[k]) as f32
            });
            (rgb, n.map(|v| v as f32))
        })
        .collect();
    Frame {
        width: view.width,
        height: view.height,
        rgb: shaded.iter().map(|s| s.0).collect(),
        normals: shaded.iter().map(|s| s.1).collect(),
        depth: hits.iter().map(|h| h.unwrap_or(f64::INFINITY)).collect(),
        stats,
    }
}

#[allow(clippy::too_many_arguments)]
fn in_shadow(
    field: &Field,
    view: &View,
    method: &Method,
    p: [f64; 3],
    n: [f64; 3],
    l: [f64; 3],
    t: f64,
    scale: f64,
) -> bool {
    // Leave the surface by a distance far below a pixel's footprint.
    let eps = 1e-5 * t.max(scale * 1e-3);
    let o: [f64; 3] = std::array::from_fn(|k| p[k] + eps * n[k]);
    let far = view.far.max(t) * 2.0;
    match method {
        Method::Reference => reference::first_hit(field, o, l, eps, far).is_some(),
        Method::Rmlrc(params) => {
            let min_cell = view.pixel_angle() / (1u64 << params.refine) as f64;
            rmlrc::occluded(field, params.bound, o, l, eps, far, min_cell)
        }
    }
}
