//! `relume-bake freeform …`: render a freeform (function-based) scene by the exact reference or
//! by recursive multilevel ray casting. Thin: parse, check, call the library, write atomically.

use clap::{Args, Subcommand, ValueEnum};
use rayon::prelude::*;
use relume::atmosphere::frame::air_frame;
use relume::atmosphere::lut::Luts;
use relume::atmosphere::twin::AtmosphereGpu;
use relume::baked::images::{self, check_extension};
use relume::error::exit;
use relume::freeform::{self, Bound, Field, Lighting, Method, RmlrcParams, View};
use relume::render::freeform_shade::{
    air_placement, themed_albedo, through_air, FreeformAir, ThemeView,
};
use relume::render::tonemap::linear_to_srgb8;
use relume::scene::freeform::FreeformCamera;
use relume::{Error, Result};
use serde_json::json;
use std::path::PathBuf;
use std::time::Instant;

const SCENE_HELP: &str = "\
Scene files are RON (scenes/freeform/*.ron); the format is in docs/freeform.md.
Camera: --camera EYE:TARGET:FOV, e.g. 0,2,6:0,0,0:45 (y up). Sun: --sun AZ,EL in degrees,
azimuth clockwise from north (−z), elevation above the horizon (xz plane).";

#[derive(Subcommand)]
pub enum FreeformCommand {
    /// Ray cast a freeform scene to an image (and a depth map)
    #[command(after_help = SCENE_HELP)]
    Render(RenderArgs),
    /// Polygonise a freeform scene to a triangle mesh (.obj) within a distance tolerance
    #[command(after_help = SCENE_HELP)]
    Mesh(MeshArgs),
}

#[derive(Args)]
pub struct MeshArgs {
    /// Freeform scene (.ron)
    pub scene: PathBuf,
    /// Largest distance from the mesh to the surface (scene units)
    #[arg(long, value_name = "E")]
    pub tolerance: f64,
    /// Box to mesh, LO:HI, e.g. -2,-2,-2:2,2,2 (surfaces are cut at its faces)
    #[arg(long, value_name = "LO:HI", value_parser = parse_box, allow_hyphen_values = true, default_value = "-2,-2,-2:2,2,2")]
    pub bounds: ([f64; 3], [f64; 3]),
    /// Mesh to write (.obj)
    #[arg(long, value_name = "MESH.obj")]
    pub out: PathBuf,
}

fn parse_box(s: &str) -> Result<([f64; 3], [f64; 3]), String> {
    let (a, b) = s
        .split_once(':')
        .ok_or("expected LO:HI, e.g. -2,-2,-2:2,2,2")?;
    Ok((triple(a)?, triple(b)?))
}

#[derive(Clone, Copy, ValueEnum)]
pub enum MethodArg {
    /// Exact per-ray root isolation (certified; the reference)
    Reference,
    /// Recursive multilevel ray casting (--bound, --top-level, --refine)
    Rmlrc,
}

#[derive(Args)]
pub struct RenderArgs {
    /// Freeform scene (.ron)
    pub scene: PathBuf,
    /// Image size, WIDTHxHEIGHT
    #[arg(long, value_name = "WxH", value_parser = relume::pipeline::checks::arg::wxh, default_value = "640x480")]
    pub size: (usize, usize),
    /// Camera EYE:TARGET:FOV (overrides the scene's)
    #[arg(long, value_name = "EYE:TARGET:FOV", value_parser = parse_camera, allow_hyphen_values = true)]
    pub camera: Option<FreeformCamera>,
    /// Sun AZ,EL in degrees (overrides the scene's)
    #[arg(long, value_name = "AZ,EL", value_parser = parse_sun, allow_hyphen_values = true)]
    pub sun: Option<(f64, f64)>,
    /// Image to write (.png, sRGB)
    #[arg(long, value_name = "IMG.png")]
    pub out: PathBuf,
    /// Also write the distance along each pixel's ray (.exr, f32, +inf where it misses)
    #[arg(long, value_name = "DEPTH.exr")]
    pub depth: Option<PathBuf>,
    /// How rays are cast
    #[arg(long, value_enum, default_value_t = MethodArg::Rmlrc)]
    pub method: MethodArg,
    /// RMLRC: the bound that culls cells
    #[arg(long, value_enum)]
    pub bound: Option<Bound>,
    /// RMLRC: first tiles are 2^L pixels wide
    #[arg(long, value_name = "L", value_parser = clap::value_parser!(u32).range(0..=12))]
    pub top_level: Option<u32>,
    /// RMLRC: the finest depth cell is a pixel's angle / 2^R
    #[arg(long, value_name = "R", value_parser = clap::value_parser!(u32).range(0..=30))]
    pub refine: Option<u32>,
    /// No sun shadows
    #[arg(long)]
    pub no_shadows: bool,
    /// Morph parameter of the shape textures, in [0, 1]: heights (1 − S)·heights + S·morph_to
    #[arg(long, value_name = "S", default_value_t = 0.0)]
    pub morph: f64,
    /// For a scene with `air`: the atmosphere model of the aerial perspective and the sky, as
    /// the player draws them (docs/atmosphere.md); `none` leaves surfaces and background as is
    #[arg(long, value_enum, value_name = "MODEL", default_value_t = relume::atmosphere::Model::Hillaire)]
    pub atmosphere: relume::atmosphere::Model,
}

fn triple(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>().map_err(|e| format!("`{x}`: {e}")))
        .collect::<Result<_, _>>()?;
    <[f64; 3]>::try_from(v).map_err(|_| format!("`{s}` is not x,y,z"))
}

fn parse_camera(s: &str) -> Result<FreeformCamera, String> {
    let parts: Vec<&str> = s.split(':').collect();
    if parts.len() != 3 {
        return Err("expected EYE:TARGET:FOV, e.g. 0,2,6:0,0,0:45".into());
    }
    let fov: f64 = parts[2]
        .parse()
        .map_err(|e| format!("fov `{}`: {e}", parts[2]))?;
    let c = FreeformCamera {
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

fn parse_sun(s: &str) -> Result<(f64, f64), String> {
    let (a, e) = s.split_once(',').ok_or("expected AZ,EL, e.g. 135,40")?;
    let a: f64 = a.trim().parse().map_err(|e| format!("azimuth: {e}"))?;
    let e: f64 = e.trim().parse().map_err(|e| format!("elevation: {e}"))?;
    if !a.is_finite() || !(-90.0..=90.0).contains(&e) {
        return Err("azimuth must be finite and elevation in [-90, 90]".into());
    }
    Ok((a, e))
}

/// The camera a scene is seen through when neither it nor the command line names one.
pub fn default_camera() -> FreeformCamera {
    FreeformCamera {
        eye: [0.0, 2.0, 6.0],
        target: [0.0, 0.0, 0.0],
        fov: 45.0,
        near: None,
        far: None,
    }
}

pub fn run(cmd: &FreeformCommand, json: bool, quiet: bool) -> Result<i32> {
    match cmd {
        FreeformCommand::Render(a) => render(a, json, quiet),
        FreeformCommand::Mesh(a) => mesh(a, json, quiet),
    }
}

fn render(a: &RenderArgs, json: bool, quiet: bool) -> Result<i32> {
    check_extension(&a.out, &["png"])?;
    if let Some(d) = &a.depth {
        check_extension(d, &["exr"])?;
    }
    if !(0.0..=1.0).contains(&a.morph) {
        return Err(Error::knob(format!(
            "--morph must be in [0, 1], got {}",
            a.morph
        )));
    }
    let scene = relume::load::freeform_scene(&a.scene)?;
    let mut field = Field::compile(&scene.shape).map_err(|e| Error::input(&a.scene, e))?;
    field.set_morph(a.morph);
    let camera = a
        .camera
        .clone()
        .or(scene.camera.clone())
        .unwrap_or_else(default_camera);
    let (w, h) = (a.size.0 as u32, a.size.1 as u32);
    let view = View::new(&camera, w, h);
    let (az, el) = a
        .sun
        .or(scene.sun.map(|s| (s.azimuth, s.elevation)))
        .unwrap_or((135.0, 45.0));
    let d = RmlrcParams::default();
    let params = RmlrcParams {
        bound: a.bound.unwrap_or(d.bound),
        top_level: a.top_level.unwrap_or(d.top_level),
        refine: a.refine.unwrap_or(d.refine),
    };
    let method = match a.method {
        MethodArg::Reference => Method::Reference,
        MethodArg::Rmlrc => Method::Rmlrc(params),
    };
    let sun = freeform::shade::sun_direction(az, el);
    // The scene's air, by the player's twin (render::freeform_shade::through_air).
    let atm = relume::atmosphere::Atmosphere::earth();
    let air = scene.air.map(|sa| {
        let (alt, sun_f64, range) =
            air_placement(&sa, view.eye[1], view.far, sun.map(|v| v as f32), &atm);
        let frame = air_frame(&atm, a.atmosphere, sun_f64, alt, 0.0, 1.0);
        let luts = (a.atmosphere == relume::atmosphere::Model::Hillaire)
            .then(|| Luts::build(&AtmosphereGpu::new(&atm, alt, sun_f64, range)));
        (frame, (sa.metres_per_unit / 1000.0) as f32, luts)
    });
    let light = Lighting {
        sun,
        sun_colour: air.as_ref().map_or([1.0; 3], |(f, _, _)| {
            std::array::from_fn(|k| f.sun_light[k] as f64)
        }),
        ambient: scene.ambient,
        background: scene.background,
        shadows: !a.no_shadows,
    };
    // The scene's thematic textures, by the player's twin (render::freeform_shade).
    let themes = match &scene.themes {
        Some(t) => {
            let file = a
                .scene
                .parent()
                .unwrap_or(std::path::Path::new("."))
                .join(&t.file);
            Some((
                relume::load::themes::load_themes(&file, None)?,
                t.projection.packed(),
            ))
        }
        None => None,
    };
    let theme_view = themes.as_ref().map(|(set, (kind, projection))| ThemeView {
        look: set.lookup(0),
        kind: *kind,
        projection: *projection,
        eye: view.eye.map(|v| v as f32),
        pixel_angle: 2.0 * view.tan_x as f32 / w as f32,
    });
    let albedo = |d: [f64; 3], t: f64| {
        let tv = theme_view.as_ref().expect("only called with themes");
        themed_albedo(tv, d.map(|v| v as f32), t as f32).map(|v| v as f64)
    };
    let t0 = Instant::now();
    let frame = freeform::shade::render_with(
        &field,
        &view,
        &method,
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
    let seconds = t0.elapsed().as_secs_f64();
    let mut img = image::RgbaImage::new(w, h);
    for (px, rgb) in img.pixels_mut().zip(&rgb) {
        let [r, g, b] = rgb.map(linear_to_srgb8);
        *px = image::Rgba([r, g, b, 255]);
    }
    images::write_png_rgba(&a.out, &img)?;
    if let Some(d) = &a.depth {
        let depth: Vec<f32> = frame.depth.iter().map(|&t| t as f32).collect();
        images::write_exr_gray(d, w as usize, h as usize, &depth)?;
    }
    let pixels = (w as u64 * h as u64) as f64;
    let (leaves, perturbations) = scene.counts();
    if json {
        let j = json!({
            "scene": a.scene.display().to_string(),
            "out": a.out.display().to_string(),
            "depth": a.depth.as_ref().map(|d| d.display().to_string()),
            "width": w, "height": h,
            "method": match a.method { MethodArg::Reference => "reference", MethodArg::Rmlrc => "rmlrc" },
            "rmlrc": matches!(a.method, MethodArg::Rmlrc).then_some(params),
            "surfaces": leaves, "perturbations": perturbations,
            "seconds": seconds,
            "hit_pixels": frame.hits(),
            "nodes_visited": frame.stats.nodes,
            "nodes_per_pixel": frame.stats.nodes as f64 / pixels,
            "nodes_per_level": frame.stats.nodes_per_level,
            "bound_terms_per_pixel": frame.stats.bound_terms as f64 / pixels,
            "point_evals_per_pixel": frame.stats.point_evals as f64 / pixels,
        });
        println!("{}", serde_json::to_string_pretty(&j).expect("json"));
    } else if !quiet {
        eprintln!(
            "rendered {} ({w}x{h}, {} of {} pixels hit) in {seconds:.2} s{}",
            a.out.display(),
            frame.hits(),
            w as u64 * h as u64,
            if matches!(a.method, MethodArg::Rmlrc) {
                format!(
                    "; {:.1} nodes and {:.1} point evaluations per pixel",
                    frame.stats.nodes as f64 / pixels,
                    frame.stats.point_evals as f64 / pixels
                )
            } else {
                String::new()
            }
        );
    }
    Ok(exit::OK)
}

fn mesh(a: &MeshArgs, json: bool, quiet: bool) -> Result<i32> {
    use relume::freeform::mesh::{self, MeshParams};
    check_extension(&a.out, &["obj"])?;
    let scene = relume::load::freeform_scene(&a.scene)?;
    let field = Field::compile(&scene.shape).map_err(|e| Error::input(&a.scene, e))?;
    let params = MeshParams {
        lo: a.bounds.0,
        hi: a.bounds.1,
        tolerance: a.tolerance,
    };
    let t0 = Instant::now();
    let (m, stats) = mesh::polygonise_with_stats(&field, &params)?;
    let seconds = t0.elapsed().as_secs_f64();
    images::write_atomic(&a.out, |tmp| {
        let mut f = std::fs::File::create(tmp).map_err(|e| Error::io(tmp, "cannot create", e))?;
        mesh::write_obj(&m, &mut f).map_err(|e| Error::io(tmp, "cannot write", e))
    })?;
    let obj = mesh::obj_bytes(&m);
    let ron = std::fs::metadata(&a.scene).map(|m| m.len()).unwrap_or(0);
    // The height samples a textured scene describes (f32 each), beside its RON text.
    let texture_bytes: usize = field.textures.iter().map(|t| 4 * t.heights.len()).sum();
    if json {
        let j = json!({
            "scene": a.scene.display().to_string(), "out": a.out.display().to_string(),
            "tolerance": a.tolerance, "triangles": m.triangles.len(), "vertices": m.positions.len(),
            "obj_bytes": obj, "scene_bytes": ron, "seconds": seconds,
            "spacing": stats.spacing, "crease": stats.crease, "grid": stats.grid,
            "method": if stats.subdivision > 0 { "carrier-grid" } else { "marching-tetrahedra" },
            "subdivision": stats.subdivision, "texture_bytes": texture_bytes,
        });
        println!("{}", serde_json::to_string_pretty(&j).expect("json"));
    } else if !quiet {
        eprintln!(
            "meshed {} ({} triangles, {} bytes of OBJ against {ron} bytes of scene) in {seconds:.2} s",
            a.out.display(),
            m.triangles.len(),
            obj
        );
    }
    Ok(exit::OK)
}
