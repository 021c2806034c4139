//! The one place where knob ranges are checked. Each check is a plain function over the value;
//! the serde adaptors in [`de`] call it while a pipeline file is parsed (so an error carries the
//! knob's line and column), and the `parse_*` functions call it for command-line flags (clap
//! `value_parser`s). Neither restates a range.

use crate::radiosity::patches::voxelize::Resolution;
use crate::radiosity::transport::Bounces;
use std::str::FromStr;

/// A check: the value back when it is in range, else the message.
pub type Check<T> = fn(T) -> Result<T, String>;

/// A finite f32 greater than zero.
pub fn positive_f32(v: f32) -> Result<f32, String> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!(
            "out of range: {v} (must be a positive finite number)"
        ))
    }
}

/// A finite f64 greater than zero.
pub fn positive_f64(v: f64) -> Result<f64, String> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!(
            "out of range: {v} (must be a positive finite number)"
        ))
    }
}

/// A count of at least 1.
pub fn at_least_one(v: u32) -> Result<u32, String> {
    if v >= 1 {
        Ok(v)
    } else {
        Err(format!("out of range: {v} (must be at least 1)"))
    }
}

/// A percentage in [0, 100].
pub fn percent(v: f64) -> Result<f64, String> {
    if (0.0..=100.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("out of range: {v} (a percentage in [0, 100])"))
    }
}

/// Horizon-map azimuths: 1..=360.
pub fn horizon_directions(v: u32) -> Result<u32, String> {
    if (1..=360).contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "out of range: {v} (horizon directions are 1..=360)"
        ))
    }
}

/// Reorder passes: 0, 1 or 2.
pub fn reorder_passes(v: u8) -> Result<u8, String> {
    if v <= 2 {
        Ok(v)
    } else {
        Err(format!("out of range: {v} (reorder passes are 0, 1 or 2)"))
    }
}

/// A texture side: a multiple of 4, at least 4.
pub fn texture_size(v: u32) -> Result<u32, String> {
    if v >= 4 && v.is_multiple_of(4) {
        Ok(v)
    } else {
        Err(format!(
            "out of range: {v} (a texture size is a positive multiple of 4)"
        ))
    }
}

/// A cell size: both sides positive and finite.
pub fn cell_size(v: (f64, f64)) -> Result<(f64, f64), String> {
    let (x, y) = v;
    if x.is_finite() && y.is_finite() && x > 0.0 && y > 0.0 {
        Ok(v)
    } else {
        Err(format!(
            "out of range: cell size {v:?} (both must be positive finite numbers)"
        ))
    }
}

/// `VoxelSize(s)` with s positive and finite, `TargetPatches(n)` with n ≥ 1, or `Adaptive(..)`
/// with the ranges of [`crate::radiosity::patches::adaptive::AdaptiveParams::check`].
pub fn resolution(v: Resolution) -> Result<Resolution, String> {
    match v {
        Resolution::VoxelSize(s) if !(s.is_finite() && s > 0.0) => Err(format!(
            "out of range: VoxelSize({s}) (must be a positive finite number)"
        )),
        Resolution::TargetPatches(0) => {
            Err("out of range: TargetPatches(0) (must be at least 1)".into())
        }
        Resolution::Adaptive(a) => a.check().map(|()| v),
        v => Ok(v),
    }
}

/// `Finite(k)` with k ≥ 1, `Infinite`, or `Auto(tol)` with tol positive and finite.
pub fn bounces(v: Bounces) -> Result<Bounces, String> {
    match v {
        Bounces::Finite(0) => {
            Err("out of range: Finite(0) (at least one bounce; Infinite for all)".into())
        }
        Bounces::Auto(t) if !(t.is_finite() && t > 0.0) => Err(format!(
            "out of range: Auto({t}) (the tolerance must be a positive finite number)"
        )),
        v => Ok(v),
    }
}

/// Parse a command-line value and check it.
pub fn parse_checked<T: FromStr>(s: &str, check: Check<T>) -> Result<T, String> {
    let v = s
        .trim()
        .parse::<T>()
        .map_err(|_| format!("`{s}` is not a number"))?;
    check(v)
}

/// Command-line parsers (clap `value_parser`s) over the same checks.
pub mod arg {
    use super::*;

    pub fn positive_f32(s: &str) -> Result<f32, String> {
        parse_checked(s, super::positive_f32)
    }
    pub fn positive_f64(s: &str) -> Result<f64, String> {
        parse_checked(s, super::positive_f64)
    }
    pub fn at_least_one(s: &str) -> Result<u32, String> {
        parse_checked(s, super::at_least_one)
    }
    pub fn percent(s: &str) -> Result<f64, String> {
        parse_checked(s, super::percent)
    }
    pub fn reorder_passes(s: &str) -> Result<u8, String> {
        parse_checked(s, super::reorder_passes)
    }
    pub fn horizon_directions(s: &str) -> Result<u32, String> {
        parse_checked(s, super::horizon_directions)
    }
    pub fn texture_size(s: &str) -> Result<u32, String> {
        parse_checked(s, super::texture_size)
    }

    /// Bounces: a count k ≥ 1, `inf`, or `auto:TOL`.
    pub fn bounces(s: &str) -> Result<Bounces, String> {
        let t = s.trim().to_ascii_lowercase();
        if t == "inf" || t == "infinite" {
            return Ok(Bounces::Infinite);
        }
        if let Some(tol) = t.strip_prefix("auto:") {
            return match tol.parse::<f64>() {
                Ok(v) => super::bounces(Bounces::Auto(v)),
                Err(_) => Err(format!("`{tol}` is not a positive tolerance")),
            };
        }
        match t.parse::<u32>() {
            Ok(0) => Err("out of range: 0 (at least one bounce; `inf` for all)".into()),
            Ok(k) => Ok(Bounces::Finite(k)),
            _ => Err(format!(
                "`{s}` is not a bounce count (k ≥ 1, `inf` or `auto:TOL`)"
            )),
        }
    }

    /// `WIDTHxHEIGHT`, both at least 1.
    pub fn wxh(s: &str) -> Result<(usize, usize), String> {
        let (w, h) = s
            .split_once(['x', 'X'])
            .ok_or_else(|| format!("`{s}` is not WIDTHxHEIGHT (e.g. 1024x512)"))?;
        let w: usize = w.parse().map_err(|_| format!("`{w}` is not a width"))?;
        let h: usize = h.parse().map_err(|_| format!("`{h}` is not a height"))?;
        if w == 0 || h == 0 {
            return Err("width and height must be at least 1".into());
        }
        Ok((w, h))
    }

    use crate::render::camera::Camera;
    use crate::terrain::Sun;

    /// `WIDTHxHEIGHT`, each in 1..=16384.
    pub fn frame_size(s: &str) -> Result<(u32, u32), String> {
        let (w, h) = wxh(s)?;
        if w > 16384 || h > 16384 {
            return Err("width and height must be in 1..=16384".into());
        }
        Ok((w as u32, h as u32))
    }

    fn floats(s: &str) -> Result<Vec<f32>, String> {
        s.split(',')
            .map(|t| {
                t.trim()
                    .parse::<f32>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| format!("`{t}` is not a finite number"))
            })
            .collect()
    }

    /// `AZIMUTH,ELEVATION` in degrees, elevation in [−90, 90].
    pub fn sun(s: &str) -> Result<Sun, String> {
        match floats(s)?.as_slice() {
            [az, el] if (-90.0..=90.0).contains(el) => Ok(Sun {
                azimuth_deg: *az as f64,
                elevation_deg: *el as f64,
            }),
            [_, el] => Err(format!("elevation {el} is outside -90..=90 degrees")),
            _ => Err(format!("`{s}` is not AZIMUTH,ELEVATION (e.g. 135,30)")),
        }
    }

    /// `EX,EY,EZ,TX,TY,TZ[,FOV]`: eye, target and the vertical field of view in degrees.
    pub fn camera(s: &str) -> Result<Camera, String> {
        let v = floats(s)?;
        if v.len() != 6 && v.len() != 7 {
            return Err(format!(
                "`{s}` needs 6 or 7 numbers: eye x,y,z, target x,y,z[, fov]"
            ));
        }
        let eye = glam::Vec3::new(v[0], v[1], v[2]);
        let target = glam::Vec3::new(v[3], v[4], v[5]);
        let d = (target - eye).length();
        if d <= 0.0 {
            return Err("eye and target must differ".into());
        }
        let fov = v.get(6).copied().unwrap_or(39.3077);
        if !(1.0..=170.0).contains(&fov) {
            return Err(format!("field of view {fov} is outside 1..=170 degrees"));
        }
        Ok(Camera {
            eye,
            target,
            up: glam::Vec3::Y,
            fov_y_deg: fov,
            near: d * 1e-3,
            far: d * 100.0,
        })
    }

    /// `X,Y,Z`: three numbers.
    pub fn triple(s: &str) -> Result<[f64; 3], String> {
        let v: Vec<f64> = s
            .split(',')
            .map(|x| x.trim().parse::<f64>().map_err(|e| format!("`{x}`: {e}")))
            .collect::<Result<_, _>>()?;
        <[f64; 3]>::try_from(v).map_err(|_| format!("`{s}` is not x,y,z"))
    }

    /// A box `LO:HI`, each corner `X,Y,Z` (e.g. `-2,-2,-2:2,2,2`).
    pub fn box3(s: &str) -> Result<([f64; 3], [f64; 3]), String> {
        let (a, b) = s
            .split_once(':')
            .ok_or("expected LO:HI, e.g. -2,-2,-2:2,2,2")?;
        Ok((triple(a)?, triple(b)?))
    }

    /// A freeform camera `EYE:TARGET:FOV` (e.g. `0,2,6:0,0,0:45`): distinct finite eye and
    /// target, the horizontal field of view in (0, 180) degrees.
    pub fn freeform_camera(s: &str) -> Result<crate::scene::freeform::FreeformCamera, String> {
        let parts: Vec<&str> = s.split(':').collect();
        if parts.len() != 3 {
            return Err("expected EYE:TARGET:FOV, e.g. 0,2,6:0,0,0:45".into());
        }
        let fov: f64 = parts[2]
            .parse()
            .map_err(|e| format!("fov `{}`: {e}", parts[2]))?;
        let c = crate::scene::freeform::FreeformCamera {
            eye: triple(parts[0])?,
            target: triple(parts[1])?,
            fov,
            near: None,
            far: None,
        };
        if !(fov > 0.0 && fov < 180.0)
            || c.eye == c.target
            || !c.eye.iter().chain(&c.target).all(|v| v.is_finite())
        {
            return Err("need distinct finite eye and target and a fov in (0, 180)".into());
        }
        Ok(c)
    }

    /// A freeform scene's sun `AZ,EL` in degrees: a finite azimuth, an elevation in
    /// [−90, 90] (f64 throughout, unlike [`sun`]).
    pub fn freeform_sun(s: &str) -> Result<Sun, String> {
        let (a, e) = s.split_once(',').ok_or("expected AZ,EL, e.g. 135,40")?;
        let a: f64 = a.trim().parse().map_err(|e| format!("azimuth: {e}"))?;
        let e: f64 = e.trim().parse().map_err(|e| format!("elevation: {e}"))?;
        if !a.is_finite() || !(-90.0..=90.0).contains(&e) {
            return Err("azimuth must be finite and elevation in [-90, 90]".into());
        }
        Ok(Sun {
            azimuth_deg: a,
            elevation_deg: e,
        })
    }

    /// A finite number.
    pub fn finite(s: &str) -> Result<f64, String> {
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(format!("`{s}` is not a finite number")),
        }
    }

    /// A finite number greater than 0 (the message names the text as given).
    pub fn finite_positive(s: &str) -> Result<f64, String> {
        match finite(s)? {
            v if v > 0.0 => Ok(v),
            _ => Err(format!("`{s}` must be greater than 0")),
        }
    }

    /// A sun elevation in degrees, in [−90, 90].
    pub fn elevation(s: &str) -> Result<f64, String> {
        match finite(s)? {
            v if (-90.0..=90.0).contains(&v) => Ok(v),
            _ => Err(format!("sun elevation `{s}` is not in [-90, 90] degrees")),
        }
    }
}

/// serde adaptors (`deserialize_with`) over the same checks.
pub mod de {
    use super::*;
    use serde::{de::Error, Deserialize, Deserializer};

    fn with<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
        d: D,
        check: Check<T>,
    ) -> Result<T, D::Error> {
        check(T::deserialize(d)?).map_err(D::Error::custom)
    }

    fn optional<'de, D: Deserializer<'de>, T: Deserialize<'de>>(
        d: D,
        check: Check<T>,
    ) -> Result<Option<T>, D::Error> {
        Option::<T>::deserialize(d)?
            .map(check)
            .transpose()
            .map_err(D::Error::custom)
    }

    pub fn positive_f32<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
        with(d, super::positive_f32)
    }
    pub fn optional_positive_f64<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        optional(d, super::positive_f64)
    }
    pub fn optional_cell_size<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<Option<(f64, f64)>, D::Error> {
        optional(d, super::cell_size)
    }
    pub fn at_least_one<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
        with(d, super::at_least_one)
    }
    pub fn optional_at_least_one<'de, D: Deserializer<'de>>(d: D) -> Result<Option<u32>, D::Error> {
        optional(d, super::at_least_one)
    }
    pub fn percent<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        with(d, super::percent)
    }
    pub fn reorder_passes<'de, D: Deserializer<'de>>(d: D) -> Result<u8, D::Error> {
        with(d, super::reorder_passes)
    }
    pub fn horizon_directions<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
        with(d, super::horizon_directions)
    }
    pub fn texture_size<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
        with(d, super::texture_size)
    }
    pub fn resolution<'de, D: Deserializer<'de>>(d: D) -> Result<Resolution, D::Error> {
        with(d, super::resolution)
    }
    pub fn bounces<'de, D: Deserializer<'de>>(d: D) -> Result<Bounces, D::Error> {
        with(d, super::bounces)
    }

    /// Punctual lights, each checked by [`crate::scene::punctual::LightSpec::to_light`].
    pub fn lights<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<Vec<crate::scene::punctual::LightSpec>, D::Error> {
        let v = Vec::<crate::scene::punctual::LightSpec>::deserialize(d)?;
        for (k, l) in v.iter().enumerate() {
            if let Err(e) = l.to_light("") {
                return Err(D::Error::custom(format!("light {k}: {e}")));
            }
        }
        Ok(v)
    }
}
