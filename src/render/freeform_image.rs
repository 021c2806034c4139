//! The CPU picture of a freeform scene (`relume-bake freeform render`): the f64 caster and
//! shading of `freeform::shade`, the scene's thematic textures and its air by the player's
//! twins (`render::freeform_shade`), so that it draws what `relume-player SCENE.ron` draws.

use crate::atmosphere::frame::air_frame;
use crate::atmosphere::lut::Luts;
use crate::atmosphere::twin::AtmosphereGpu;
use crate::atmosphere::{Atmosphere, Model};
use crate::freeform::shade::{render_with, sun_direction, Frame, Lighting};
use crate::freeform::{Field, Method, View};
use crate::render::freeform_shade::{
    air_placement, themed_albedo, through_air, FreeformAir, ThemeView,
};
use crate::render::tonemap::linear_to_srgb8;
use crate::scene::freeform::{FreeformCamera, FreeformScene};
use crate::terrain::sun::Sun;
use crate::theme::ThemeSet;
use rayon::prelude::*;

/// The sun of a freeform scene when neither the scene nor the command line gives one: the
/// CPU renderer and the player both start from it.
pub const DEFAULT_SUN: Sun = Sun {
    azimuth_deg: 135.0,
    elevation_deg: 35.0,
};

/// The camera a freeform scene is seen through when neither it nor the command line names one:
/// from (0, 2, 6) toward the origin, 45° wide.
pub fn default_camera() -> FreeformCamera {
    FreeformCamera {
        eye: [0.0, 2.0, 6.0],
        target: [0.0, 0.0, 0.0],
        fov: 45.0,
        near: None,
        far: None,
    }
}

/// What to draw: the compiled field (morph already set), the scene it came from (background,
/// ambient, themes' projection, air), the view, the caster, the sun, whether the sun casts
/// shadows, the atmosphere model for a scene with `air`, and the scene's loaded theme set
/// (required when the scene names one, ignored otherwise).
pub struct FreeformPicture<'a> {
    pub field: &'a Field,
    pub scene: &'a FreeformScene,
    pub view: &'a View,
    pub method: &'a Method,
    pub sun: Sun,
    pub shadows: bool,
    pub atmosphere: Model,
    pub themes: Option<&'a ThemeSet>,
}

/// A drawn picture: the caster's frame (its linear RGB before the air, depths, normals and
/// counts) and the linear RGB after the air, row by row.
pub struct FreeformImage {
    pub frame: Frame,
    pub rgb: Vec<[f32; 3]>,
}

impl FreeformImage {
    /// The picture as 8-bit sRGB with opaque alpha (`render::tonemap::linear_to_srgb8`).
    pub fn to_rgba8(&self) -> image::RgbaImage {
        let mut img = image::RgbaImage::new(self.frame.width, self.frame.height);
        for (px, rgb) in img.pixels_mut().zip(&self.rgb) {
            let [r, g, b] = rgb.map(linear_to_srgb8);
            *px = image::Rgba([r, g, b, 255]);
        }
        img
    }
}

/// Draw `p`: cast every pixel of the view, shade it (themed when the scene has themes), then
/// carry it through the scene's air by the chosen atmosphere model (Hillaire's builds its
/// tables first). Panics when the scene names themes and `p.themes` is `None`.
pub fn render_freeform(p: &FreeformPicture) -> FreeformImage {
    let view = p.view;
    let w = view.width;
    let sun = sun_direction(p.sun.azimuth_deg, p.sun.elevation_deg);
    let atm = Atmosphere::earth();
    let air = p.scene.air.map(|sa| {
        let (alt, sun_f64, range) =
            air_placement(&sa, view.eye[1], view.far, sun.map(|v| v as f32), &atm);
        let frame = air_frame(&atm, p.atmosphere, sun_f64, alt, 0.0, 1.0);
        let luts = (p.atmosphere == Model::Hillaire)
            .then(|| Luts::build(&AtmosphereGpu::new(&atm, alt, sun_f64, range)));
        (frame, (sa.metres_per_unit / 1000.0) as f32, luts)
    });
    let light = Lighting {
        sun,
        sun_colour: air.as_ref().map_or([1.0; 3], |(f, _, _)| {
            std::array::from_fn(|k| f.sun_light[k] as f64)
        }),
        ambient: p.scene.ambient,
        background: p.scene.background,
        shadows: p.shadows,
    };
    let theme_view = p.scene.themes.as_ref().map(|t| {
        let set = p.themes.expect("a scene with themes needs its theme set");
        let (kind, projection) = t.projection.packed();
        ThemeView {
            look: set.lookup(0),
            kind,
            projection,
            eye: view.eye.map(|v| v as f32),
            pixel_angle: 2.0 * view.tan_x as f32 / w as f32,
        }
    });
    let albedo = |d: [f64; 3], t: f64| {
        let tv = theme_view.as_ref().expect("only called with themes");
        themed_albedo(tv, d.map(|v| v as f32), t as f32).map(|v| v as f64)
    };
    let frame = render_with(
        p.field,
        view,
        p.method,
        &light,
        theme_view.is_some().then_some(&albedo as _),
    );
    let mut rgb = frame.rgb.clone();
    if let Some((f, km, luts)) = &air {
        let fa = FreeformAir {
            frame: *f,
            km_per_unit: *km,
            luts: luts.as_ref(),
        };
        let s32 = sun.map(|v| v as f32);
        rgb.par_iter_mut().enumerate().for_each(|(i, c)| {
            let (d, _) = view.pixel_ray(i as u32 % w, i as u32 / w);
            let t = frame.depth[i];
            let t = t.is_finite().then_some(t as f32);
            *c = through_air(*c, d.map(|v| v as f32), t, s32, &fa);
        });
    }
    FreeformImage { frame, rgb }
}
