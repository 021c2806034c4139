//! The air's part of a frame: the uniform fields every renderer of relume hands its shaders
//! (terrain: `shaders/terrain_render.wgsl`; freeform surfaces: `shaders/freeform_shade.wgsl`)
//! for one model, sun and eye altitude.
//!
//! Units: surfaces are shaded as albedo × (E·cos + sky), without the 1/π of a Lambertian
//! surface, so the air's radiance is multiplied by π (`fog_sun.w`) to match. The sun lighting
//! surfaces is the top-of-air sun for the constant-density fog (its assumption) and, for
//! Hillaire's, the sun seen through the air from the ground's altitude (f64 quadrature,
//! `reference::sun_transmittance`): low suns redden and dim.

use super::fog::FogParams;
use super::{eye_position, reference, Atmosphere, Model};
use glam::DVec3;

/// The air's uniform fields of a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AirFrame {
    /// RGB: the sun's illuminance on surfaces (× strength); w: the sky (ambient) term.
    pub sun_light: [f32; 4],
    /// The constant-density fog: extinction per km (RGB), w: Mie g.
    pub fog_ext: [f32; 4],
    /// Rayleigh scattering per km (RGB).
    pub fog_rayleigh: [f32; 4],
    /// Mie scattering per km (RGB).
    pub fog_mie: [f32; 4],
    /// Sun illuminance lighting the air (RGB), w: the radiance scale (π).
    pub fog_sun: [f32; 4],
    /// 0 none, 1 constant-density fog per vertex, 2 per pixel, 3 Hillaire.
    pub model: u32,
}

/// The sky (ambient) term of the terrain's lighting with the sun at the zenith. Under Hillaire's
/// model it follows the sun's transmittance to the ground, relative to the zenith's: a clear
/// sky's diffuse irradiance is a fixed fraction of the direct normal irradiance (the ASHRAE
/// clear-sky model, DHI = C·DNI with DNI = A·exp(−B / sin elevation)), so a low sun dims the sky
/// with it and the relief's lit and shadowed slopes keep their contrast. The other models light
/// surfaces with the top-of-air sun and keep the constant.
pub const SKY: f32 = 0.15;

/// The air's uniform fields for `model` with the sun toward unit `sun` (eye frame, +Y up), the
/// eye at `eye_altitude` m, the ground (what the sun lights) at `ground_altitude` m, sun
/// strength `strength`.
pub fn air_frame(
    atm: &Atmosphere,
    model: Model,
    sun: DVec3,
    eye_altitude: f64,
    ground_altitude: f64,
    strength: f32,
) -> AirFrame {
    let f = FogParams::new(atm, eye_altitude, sun, false);
    let km = |v: [f64; 3], w: f64| {
        [
            v[0] as f32 * 1e3,
            v[1] as f32 * 1e3,
            v[2] as f32 * 1e3,
            w as f32,
        ]
    };
    let (light, sky) = match model {
        Model::Hillaire => {
            let at =
                |d: DVec3| reference::sun_transmittance(atm, eye_position(atm, ground_altitude), d);
            let luminance = |t: [f64; 3]| 0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2];
            let light = at(sun);
            let sky = SKY as f64 * luminance(light) / luminance(at(DVec3::Y)).max(1e-12);
            (light, sky as f32)
        }
        _ => ([1.0; 3], SKY),
    };
    let sun_light = std::array::from_fn(|c| {
        if c == 3 {
            sky
        } else {
            (light[c] * atm.sun_illuminance[c]) as f32 * strength
        }
    });
    AirFrame {
        sun_light,
        fog_ext: km(f.extinction, f.mie_g),
        fog_rayleigh: km(f.rayleigh, 0.0),
        fog_mie: km(f.mie, 0.0),
        fog_sun: [
            f.sun[0] as f32 * strength,
            f.sun[1] as f32 * strength,
            f.sun[2] as f32 * strength,
            std::f32::consts::PI,
        ],
        model: model.code(),
    }
}

impl Model {
    /// The shaders' number for the model: 0 none, 1 constant-density fog per
    /// vertex, 2 per pixel, 3 Hillaire.
    pub fn code(self) -> u32 {
        match self {
            Model::None => 0,
            Model::Fog => 1,
            Model::FogPerPixel => 2,
            Model::Hillaire => 3,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hillaire's sky term: the constant at the zenith, dimmer with the sun lower, in step with
    /// the direct sun's luminance; the other models keep the constant.
    #[test]
    fn the_sky_term_follows_the_sun() {
        let atm = Atmosphere::earth();
        let sun_at = |el: f64| {
            let e = el.to_radians();
            DVec3::new(0.0, e.sin(), e.cos())
        };
        let sky = |m, el| air_frame(&atm, m, sun_at(el), 500.0, 0.0, 1.0).sun_light;
        assert!((sky(Model::Hillaire, 90.0)[3] - SKY).abs() < 1e-6);
        let mut last = f32::INFINITY;
        for el in [90.0, 45.0, 20.0, 6.0, 2.0] {
            let l = sky(Model::Hillaire, el);
            assert!(l[3] < last || el == 90.0, "{el}°: {}", l[3]);
            last = l[3];
            let y = 0.2126 * l[0] + 0.7152 * l[1] + 0.0722 * l[2];
            let y90 = {
                let z = sky(Model::Hillaire, 90.0);
                0.2126 * z[0] + 0.7152 * z[1] + 0.0722 * z[2]
            };
            assert!(
                (l[3] / y - SKY / y90).abs() < 1e-4,
                "{el}°: sky/direct not constant"
            );
            assert_eq!(sky(Model::Fog, el)[3], SKY);
        }
    }
}
