//! Punctual lights from the command line (`relume-player --light SPEC`), in scene units and
//! KHR_lights_punctual semantics (the same [`Light`] a glTF file gives):
//!
//! - `point:X,Y,Z[:INTENSITY[:R,G,B]]` — candela, default 1;
//! - `spot:X,Y,Z:DX,DY,DZ:ANGLE[:INTENSITY[:R,G,B]]` — ANGLE = the cone's outer half-angle in
//!   degrees (0, 90]; the inner cone is 80 % of it; candela, default 1;
//! - `dir:DX,DY,DZ[:INTENSITY[:R,G,B]]` — the direction the light travels; lux, default 3 (the
//!   player's sun).
//!
//! Colours are linear RGB, default white.

use crate::scene::{Light, LightKind};

/// Parse one `--light` value. The error says what is wrong and shows the expected form.
pub fn parse_light(spec: &str) -> std::result::Result<Light, String> {
    let parts: Vec<&str> = spec.split(':').collect();
    let forms = "expected point:X,Y,Z[:I[:R,G,B]], spot:X,Y,Z:DX,DY,DZ:ANGLE[:I[:R,G,B]] or dir:DX,DY,DZ[:I[:R,G,B]]";
    let (kind, fixed) = match parts[0] {
        "point" => ("point", 2),
        "spot" => ("spot", 4),
        "dir" | "directional" => ("dir", 2),
        other => return Err(format!("unknown light kind `{other}`: {forms}")),
    };
    if parts.len() < fixed || parts.len() > fixed + 2 {
        return Err(format!("`{spec}` has {} fields: {forms}", parts.len()));
    }
    let intensity = match parts.get(fixed) {
        Some(s) => {
            let v = number(s, "intensity")?;
            if v < 0.0 {
                return Err(format!("intensity must be ≥ 0, got {v}"));
            }
            v
        }
        None if kind == "dir" => 3.0,
        None => 1.0,
    };
    let color = match parts.get(fixed + 1) {
        Some(s) => {
            let c = triple(s, "colour")?;
            if c.iter().any(|v| *v < 0.0) {
                return Err(format!("colour components must be ≥ 0, got `{s}`"));
            }
            c
        }
        None => [1.0; 3],
    };
    let mut light = Light {
        name: format!("--light {spec}"),
        kind: LightKind::Point,
        position: [0.0; 3],
        direction: [0.0, -1.0, 0.0],
        color,
        intensity,
        range: None,
    };
    match kind {
        "point" => light.position = triple(parts[1], "position")?,
        "spot" => {
            light.position = triple(parts[1], "position")?;
            light.direction = unit(parts[2])?;
            let angle = number(parts[3], "cone angle")?;
            if !(angle > 0.0 && angle <= 90.0) {
                return Err(format!(
                    "the spot's cone half-angle must be in (0, 90] degrees, got {angle}"
                ));
            }
            let outer = angle.to_radians();
            light.kind = LightKind::Spot {
                inner_cone: 0.8 * outer,
                outer_cone: outer,
            };
        }
        _ => {
            light.kind = LightKind::Directional;
            light.direction = unit(parts[1])?;
        }
    }
    Ok(light)
}

fn number(s: &str, what: &str) -> std::result::Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(format!("{what} `{s}` is not a finite number")),
    }
}

fn triple(s: &str, what: &str) -> std::result::Result<[f32; 3], String> {
    let v: Vec<&str> = s.split(',').collect();
    if v.len() != 3 {
        return Err(format!("{what} `{s}` needs three comma-separated numbers"));
    }
    Ok([
        number(v[0], what)?,
        number(v[1], what)?,
        number(v[2], what)?,
    ])
}

fn unit(s: &str) -> std::result::Result<[f32; 3], String> {
    let d = glam::Vec3::from(triple(s, "direction")?);
    let len = d.length();
    if len <= 1e-12 || !len.is_finite() {
        return Err(format!("direction `{s}` has no length"));
    }
    Ok((d / len).to_array())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_kind_with_defaults() {
        let p = parse_light("point:0.3,0.5,0.2").unwrap();
        assert_eq!(p.kind, LightKind::Point);
        assert_eq!(p.position, [0.3, 0.5, 0.2]);
        assert_eq!((p.intensity, p.color), (1.0, [1.0; 3]));

        let s = parse_light("spot:0,1,0:0,-2,0:30:5:1,0.5,0.25").unwrap();
        assert_eq!(s.direction, [0.0, -1.0, 0.0]);
        let LightKind::Spot {
            inner_cone,
            outer_cone,
        } = s.kind
        else {
            panic!("not a spot")
        };
        assert!((outer_cone - 30f32.to_radians()).abs() < 1e-6 && inner_cone < outer_cone);
        assert_eq!((s.intensity, s.color), (5.0, [1.0, 0.5, 0.25]));

        let d = parse_light("dir:1,-1,0").unwrap();
        assert_eq!(d.kind, LightKind::Directional);
        assert!((d.direction[0] - std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-6);
        assert_eq!(d.intensity, 3.0);
    }

    #[test]
    fn rejects_bad_specs_with_a_reason() {
        for (spec, says) in [
            ("lamp:0,0,0", "unknown light kind"),
            ("point", "fields"),
            ("point:0,0", "three"),
            ("point:0,0,NaN", "finite"),
            ("point:0,0,0:-1", "≥ 0"),
            ("point:0,0,0:1:1,-1,1", "≥ 0"),
            ("spot:0,0,0:0,0,0:30", "no length"),
            ("spot:0,0,0:0,-1,0:120", "(0, 90]"),
            ("dir:0,-1,0:1:1,1,1:extra", "fields"),
        ] {
            let e = parse_light(spec).unwrap_err();
            assert!(e.contains(says), "{spec}: {e}");
        }
    }
}
