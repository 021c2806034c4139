//! `relume-bake freeform …`: render a freeform (function-based) scene by the exact reference or
//! by recursive multilevel ray casting. Thin: parse, check, call the library, write atomically.

use clap::{Args, Subcommand, ValueEnum};
use relume::baked::images::{self, check_extension};
use relume::error::exit;
use relume::freeform::{Bound, Field, Method, RmlrcParams, View};
use relume::pipeline::checks::arg;
use relume::render::freeform_image::{
    default_camera, render_freeform, FreeformPicture, DEFAULT_SUN,
};
use relume::scene::freeform::FreeformCamera;
use relume::terrain::Sun;
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
    #[arg(long, value_name = "LO:HI", value_parser = arg::box3, allow_hyphen_values = true, default_value = "-2,-2,-2:2,2,2")]
    pub bounds: ([f64; 3], [f64; 3]),
    /// Mesh to write (.obj)
    #[arg(long, value_name = "MESH.obj")]
    pub out: PathBuf,
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
    #[arg(long, value_name = "WxH", value_parser = arg::wxh, default_value = "640x480")]
    pub size: (usize, usize),
    /// Camera EYE:TARGET:FOV (overrides the scene's)
    #[arg(long, value_name = "EYE:TARGET:FOV", value_parser = arg::freeform_camera, allow_hyphen_values = true)]
    pub camera: Option<FreeformCamera>,
    /// Sun AZ,EL in degrees (overrides the scene's)
    #[arg(long, value_name = "AZ,EL", value_parser = arg::freeform_sun, allow_hyphen_values = true)]
    pub sun: Option<Sun>,
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
    let camera = a.camera.clone().or(scene.camera.clone());
    let (w, h) = (a.size.0 as u32, a.size.1 as u32);
    let view = View::new(&camera.unwrap_or_else(default_camera), w, h);
    let scene_sun = scene.sun.map(|s| Sun {
        azimuth_deg: s.azimuth,
        elevation_deg: s.elevation,
    });
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
    let themes = relume::load::freeform_themes(&a.scene, &scene)?;
    let t0 = Instant::now();
    let picture = render_freeform(&FreeformPicture {
        field: &field,
        scene: &scene,
        view: &view,
        method: &method,
        sun: a.sun.or(scene_sun).unwrap_or(DEFAULT_SUN),
        shadows: !a.no_shadows,
        atmosphere: a.atmosphere,
        themes: themes.as_ref(),
    });
    let seconds = t0.elapsed().as_secs_f64();
    images::write_png_rgba(&a.out, &picture.to_rgba8())?;
    let frame = &picture.frame;
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
