//! `relume-player`: render a baked directory with wgpu, in a window or headless to PNG frames.
//! Thin: arguments → options; the library (`relume::player`) does the work.

#[path = "relume-player/window.rs"]
mod window;

use clap::Parser;
use relume::error::{exit, Error, Result};
use relume::gpu::compressed_gather::DecodePath;
use relume::gpu::timing::PassTimer;
use relume::gpu::{BackendChoice, Gpu};
use relume::player::light_spec::parse_light;
use relume::player::{FrameTimes, Player, PlayerOptions, Sun, TransportChoice};
use relume::render::camera::Camera;
use relume::render::mesh_reference::FrameSettings;
use relume::scene::Light;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;

const EXIT_CODES: &str = "\
Exit codes: 0 success, 1 internal error, 2 usage, 3 invalid input, 4 I/O, 6 unsupported \
(including: no GPU adapter — install mesa-vulkan-drivers), 7 the bake failed verification.

Window keys: mouse drag or arrows orbit, wheel or +/- zoom, J/L sun azimuth, I/K sun elevation,
S sun on/off, 1 direct, 2 indirect, 3 shadows, 4 emission, 5 soft shadows, 6 fog, [ ] exposure,
Esc quit.";

#[derive(Parser)]
#[command(name = "relume-player", version, about = "Render baked relume scenes and terrain with wgpu", after_help = EXIT_CODES)]
struct Cli {
    /// Baked directory (from `relume-bake run`)
    baked_dir: PathBuf,
    /// Render without a window into --out
    #[arg(long)]
    headless: bool,
    /// Frames to render headless (the sun turns a full circle over them when --sun is given)
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100000))]
    frames: u32,
    /// Output directory for headless frames (PNG) and frames.json
    #[arg(long, value_name = "DIR", default_value = "out/frames")]
    out: PathBuf,
    /// Image size
    #[arg(long, value_name = "WxH", default_value = "640x480", value_parser = parse_wxh)]
    size: (u32, u32),
    /// Sun azimuth (degrees clockwise from north) and elevation (degrees), e.g. 135,30
    #[arg(long, value_name = "AZ,EL", value_parser = parse_sun, allow_hyphen_values = true)]
    sun: Option<Sun>,
    /// Add a punctual light (repeatable): point:X,Y,Z[:I[:R,G,B]],
    /// spot:X,Y,Z:DX,DY,DZ:ANGLE[:I[:R,G,B]] or dir:DX,DY,DZ[:I[:R,G,B]] — scene units, intensity
    /// in candela (point, spot; default 1) or lux (dir; default 3), ANGLE the cone's half-angle
    /// in degrees
    #[arg(long, value_name = "SPEC", value_parser = parse_light, allow_hyphen_values = true)]
    light: Vec<Light>,
    /// Window: close after N frames (for scripts and tests)
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    exit_after: Option<u32>,
    /// Camera: eye x,y,z, target x,y,z and optionally the vertical field of view in degrees
    #[arg(long, value_name = "EX,EY,EZ,TX,TY,TZ[,FOV]", value_parser = parse_camera, allow_hyphen_values = true)]
    camera: Option<Camera>,
    /// Graphics API (default: WGPU_BACKEND, else Vulkan then GL)
    #[arg(long, value_enum)]
    backend: Option<BackendArg>,
    /// Exposure (multiplies radiance before tone mapping)
    #[arg(long, default_value_t = 1.0)]
    exposure: f32,
    /// Multiplier of the emitters' radiance (e.g. the Cornell box light)
    #[arg(long, default_value_t = 1.0)]
    emission: f32,
    /// Leave out direct light from punctual lights
    #[arg(long)]
    no_direct: bool,
    /// Leave out baked indirect light
    #[arg(long)]
    no_indirect: bool,
    /// Leave out shadows
    #[arg(long)]
    no_shadows: bool,
    /// Terrain: soft shadows of the sun's disc (branch-and-bound) instead of hard ones
    #[arg(long)]
    soft: bool,
    /// Terrain: no aerial perspective
    #[arg(long)]
    no_fog: bool,
    /// Transport to gather from: the encoded one when the bake has it (auto), or the dense
    /// `transport.npy` reference
    #[arg(long, value_enum, default_value_t = TransportArg::Auto)]
    transport: TransportArg,
    /// How BC blocks are decoded: by the texture unit (hardware, needs BC support) or by WGSL
    /// decoders over a storage buffer (shader). Default: hardware when the adapter has it
    #[arg(long, value_enum)]
    bc_decode: Option<DecodeArg>,
    /// No progress output
    #[arg(short, long)]
    quiet: bool,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum TransportArg {
    Auto,
    Dense,
    Compressed,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum DecodeArg {
    Hardware,
    Shader,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum BackendArg {
    Vulkan,
    Gl,
    Metal,
    Dx12,
}

fn parse_wxh(s: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}` is not WIDTHxHEIGHT (e.g. 1920x1080)"))?;
    let w: u32 = w.parse().map_err(|_| format!("`{w}` is not a width"))?;
    let h: u32 = h.parse().map_err(|_| format!("`{h}` is not a height"))?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err("width and height must be in 1..=16384".into());
    }
    Ok((w, h))
}

fn floats(s: &str) -> std::result::Result<Vec<f32>, String> {
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

fn parse_sun(s: &str) -> std::result::Result<Sun, String> {
    match floats(s)?.as_slice() {
        [az, el] if (-90.0..=90.0).contains(el) => Ok(Sun {
            azimuth_deg: *az as f64,
            elevation_deg: *el as f64,
        }),
        [_, el] => Err(format!("elevation {el} is outside -90..=90 degrees")),
        _ => Err(format!("`{s}` is not AZIMUTH,ELEVATION (e.g. 135,30)")),
    }
}

fn parse_camera(s: &str) -> std::result::Result<Camera, String> {
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

fn main() {
    let cli = Cli::parse();
    let code = match run(&cli) {
        Ok(()) => exit::OK,
        Err(e) => {
            eprintln!("error: {e}");
            let mut source = std::error::Error::source(&e);
            while let Some(s) = source {
                eprintln!("  caused by: {s}");
                source = s.source();
            }
            e.exit_code()
        }
    };
    std::process::exit(code);
}

fn settings(cli: &Cli) -> FrameSettings {
    FrameSettings {
        exposure: cli.exposure,
        emission_scale: cli.emission,
        direct: !cli.no_direct,
        indirect: !cli.no_indirect,
        shadows: !cli.no_shadows,
        soft_shadows: cli.soft,
        fog: !cli.no_fog,
        ..Default::default()
    }
}

fn player_options(cli: &Cli) -> PlayerOptions {
    PlayerOptions {
        transport: match cli.transport {
            TransportArg::Auto => TransportChoice::Auto,
            TransportArg::Dense => TransportChoice::Dense,
            TransportArg::Compressed => TransportChoice::Compressed,
        },
        decode: cli.bc_decode.map(|d| match d {
            DecodeArg::Hardware => DecodePath::Hardware,
            DecodeArg::Shader => DecodePath::Shader,
        }),
    }
}

fn backend(cli: &Cli) -> Option<BackendChoice> {
    cli.backend.map(|b| match b {
        BackendArg::Vulkan => BackendChoice::Vulkan,
        BackendArg::Gl => BackendChoice::Gl,
        BackendArg::Metal => BackendChoice::Metal,
        BackendArg::Dx12 => BackendChoice::Dx12,
    })
}

fn run(cli: &Cli) -> Result<()> {
    if !cli.headless {
        return window::run(window::WindowPlan {
            dir: cli.baked_dir.clone(),
            size: cli.size,
            sun: cli.sun,
            camera: cli.camera,
            settings: settings(cli),
            backend: backend(cli),
            options: player_options(cli),
            lights: cli.light.clone(),
            exit_after: cli.exit_after,
        });
    }
    let gpu = Gpu::new(backend(cli))?;
    if !cli.quiet {
        eprintln!(
            "adapter: {} ({}, {})",
            gpu.info.name, gpu.info.backend, gpu.info.device_type
        );
    }
    let (w, h) = cli.size;
    let mut player = Player::load(&gpu, &cli.baked_dir, &player_options(cli), w, h)?;
    player.add_lights(&gpu, &cli.light)?;
    let camera = cli.camera.unwrap_or_else(|| player.default_camera());
    let s = settings(cli);
    std::fs::create_dir_all(&cli.out)
        .map_err(|e| Error::io(&cli.out, "cannot create output directory", e))?;
    let mut timer = PassTimer::new(&gpu, 48);
    let mut frames = Vec::new();
    for f in 0..cli.frames {
        let sun = cli.sun.map(|s| Sun {
            azimuth_deg: s.azimuth_deg + 360.0 * f as f64 / cli.frames as f64,
            ..s
        });
        let t0 = Instant::now();
        player.set_sun(&gpu, sun)?;
        player.render(&gpu, &camera, &s, &mut timer)?;
        let cpu_ms = t0.elapsed().as_secs_f64() * 1e3;
        let gpu_ms = timer
            .read(&gpu)?
            .into_iter()
            .map(|(n, t)| (n.to_string(), t))
            .collect();
        let img = player.read_image(&gpu)?;
        let path = cli.out.join(format!("frame_{f:04}.png"));
        write_png(&path, &img)?;
        frames.push(FrameTimes {
            frame: f,
            cpu_ms,
            gpu_ms,
        });
    }
    #[derive(Serialize)]
    struct Report<'a> {
        adapter: &'a relume::gpu::AdapterReport,
        size: [u32; 2],
        note: &'static str,
        frames: Vec<FrameTimes>,
    }
    let report = Report {
        adapter: &gpu.info,
        size: [w, h],
        note: "cpu_ms is wall time to record, submit and wait; on a software rasteriser (llvmpipe/lavapipe) these are CPU times, not GPU times",
        frames,
    };
    let json = serde_json::to_string_pretty(&report).expect("report serialises");
    write_atomic(&cli.out.join("frames.json"), json.as_bytes())?;
    if !cli.quiet {
        eprintln!(
            "wrote {} frame(s) and frames.json to {}",
            cli.frames,
            cli.out.display()
        );
    }
    Ok(())
}

fn write_png(path: &Path, img: &image::RgbaImage) -> Result<()> {
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .map_err(|e| Error::Internal(format!("PNG encoding failed: {e}")))?;
    write_atomic(path, &bytes)
}

fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = path.with_extension("relume-tmp");
    std::fs::write(&tmp, bytes).map_err(|e| Error::io(&tmp, "cannot write", e))?;
    std::fs::rename(&tmp, path).map_err(|e| Error::io(path, "cannot write", e))
}
