//! Punctual lights from the command line (`relume-player --light SPEC`), in scene units and
//! KHR_lights_punctual semantics (the same [`Light`] a glTF file gives):
//!
//! - `point:X,Y,Z[:INTENSITY[:R,G,B]]` — candela, default 1;
//! - `spot:X,Y,Z:DX,DY,DZ:ANGLE[:INTENSITY[:R,G,B]]` — ANGLE = the cone's outer half-angle in
//!   degrees (0, 90]; the inner cone is 80 % of it; candela, default 1;
//! - `dir:DX,DY,DZ[:INTENSITY[:R,G,B]]` — the direction the light travels; lux, default 3 (the
//!   player's sun).
//!
//! Colours are linear RGB, default white. The values are checked by
//! [`LightSpec::to_light`], as for lights declared in a pipeline.

use crate::scene::punctual::LightSpec;
use crate::scene::Light;

/// Parse one `--light` value. The error says what is wrong and shows the expected form.
pub fn parse_light(spec: &str) -> std::result::Result<Light, String> {
    let parts: Vec<&str> = spec.split(':').collect();
    let forms = "expected point:X,Y,Z[:I[:R,G,B]], spot:X,Y,Z:DX,DY,DZ:ANGLE[:I[:R,G,B]] or dir:DX,DY,DZ[:I[:R,G,B]]";
    let fixed = match parts[0] {
        "point" | "dir" | "directional" => 2,
        "spot" => 4,
        other => return Err(format!("unknown light kind `{other}`: {forms}")),
    };
    if parts.len() < fixed || parts.len() > fixed + 2 {
        return Err(format!("`{spec}` has {} fields: {forms}", parts.len()));
    }
    let intensity = parts
        .get(fixed)
        .map(|s| number(s, "intensity"))
        .transpose()?;
    let color = match parts.get(fixed + 1) {
        Some(s) => triple(s, "colour")?,
        None => [1.0; 3],
    };
    let light = match parts[0] {
        "point" => LightSpec::Point {
            position: triple(parts[1], "position")?,
            intensity: intensity.unwrap_or(1.0),
            color,
        },
        "spot" => LightSpec::Spot {
            position: triple(parts[1], "position")?,
            direction: triple(parts[2], "direction")?,
            angle: number(parts[3], "cone angle")?,
            intensity: intensity.unwrap_or(1.0),
            color,
        },
        _ => LightSpec::Directional {
            direction: triple(parts[1], "direction")?,
            intensity: intensity.unwrap_or(3.0),
            color,
        },
    };
    light.to_light(&format!("--light {spec}"))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::LightKind;

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
