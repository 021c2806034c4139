//! `relume-player`: render a baked directory with wgpu, in a window or headless to PNG frames.
//! Thin: arguments → options; the library (`relume::player`) does the work.

use clap::Parser;
use relume::error::{exit, Result};
use relume::gpu::compressed_gather::DecodePath;
use relume::gpu::{BackendChoice, Gpu};
use relume::pipeline::checks::arg as args;
use relume::player::headless::{render_frames, HeadlessPlan};
use relume::player::{PlayerOptions, Sun, TransportChoice};
use relume::render::camera::Camera;
use relume::render::exposure::Exposure;
use relume::render::mesh_reference::FrameSettings;
use relume::scene::light_spec::parse_light;
use relume::scene::Light;
use std::path::PathBuf;

const KEYS: &str = "\
Window keys: Tab panel on/off, F12 screenshot, mouse drag or arrows orbit, wheel or +/- zoom, J/L sun azimuth, I/K sun elevation,
S sun on/off, 1 direct, 2 indirect, 3 shadows, 4 emission, 5 soft shadows, 6 fog, 7 terrain
hard shadows from horizon maps / by traversal, 8 themes, 9 theme-border animation, 0 next
atmosphere model (fog per vertex, fog per pixel, Hillaire), [ ] exposure (automatic:\ncompensation in stops), X automatic exposure on/off,
Esc quit. Headless, frame K of --frames N shows the theme borders of animation frame K.";

fn after_help() -> String {
    format!("{}\n\n{KEYS}", exit::HELP)
}

#[derive(Parser)]
#[command(name = "relume-player", version, about = "Render baked relume scenes and terrain with wgpu", after_help = after_help())]
struct Cli {
    /// Baked directory (from `relume-bake run`), or a freeform scene (`scenes/freeform/*.ron`)
    /// cast live
    baked_dir: PathBuf,
    /// Render without a window into --out
    #[arg(long)]
    headless: bool,
    /// Frames to render headless (the sun turns a full circle over them when --sun is given;
    /// the shape textures of a freeform scene morph from their first grid to their second)
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100000))]
    frames: u32,
    /// Output directory for headless frames (PNG) and frames.json
    #[arg(long, value_name = "DIR", default_value = "out/frames")]
    out: PathBuf,
    /// Image size
    #[arg(long, value_name = "WxH", default_value = "640x480", value_parser = args::frame_size)]
    size: (u32, u32),
    /// Sun azimuth (degrees clockwise from north) and elevation (degrees), e.g. 135,30
    #[arg(long, value_name = "AZ,EL", value_parser = args::sun, allow_hyphen_values = true)]
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
    /// Window: start with the panel hidden (Tab shows it)
    #[arg(long)]
    no_panel: bool,
    /// Window: replay scripted panel input (`FRAME click LABEL`, `FRAME screenshot PNG` per
    /// line; docs/player.md) — for tests and demos
    #[arg(long, value_name = "FILE")]
    panel_script: Option<PathBuf>,
    /// Camera: eye x,y,z, target x,y,z and optionally the vertical field of view in degrees
    #[arg(long, value_name = "EX,EY,EZ,TX,TY,TZ[,FOV]", value_parser = args::camera, allow_hyphen_values = true)]
    camera: Option<Camera>,
    /// Graphics API (default: WGPU_BACKEND, else Vulkan then GL)
    #[arg(long, value_enum)]
    backend: Option<BackendChoice>,
    /// Fixed exposure (multiplies radiance before tone mapping). Default: automatic, from the
    /// frame's log-average luminance (headless: found once on frame 0 and kept)
    #[arg(long, value_name = "X", value_parser = args::positive_f32)]
    exposure: Option<f32>,
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
    /// Terrain: hard shadows by the traversal over the min/max mipmap even when the bake has
    /// horizon maps (which give them in O(1) per pixel, interpolated between stored azimuths)
    #[arg(long)]
    no_horizon: bool,
    /// Terrain and freeform scenes with `air`: no aerial perspective and no sky (same as
    /// --atmosphere none)
    #[arg(long)]
    no_fog: bool,
    /// Terrain and freeform scenes with `air`: the atmosphere model of the aerial perspective
    /// and the sky (docs/atmosphere.md)
    #[arg(long, value_enum, value_name = "MODEL", default_value_t = relume::atmosphere::Model::Hillaire)]
    atmosphere: relume::atmosphere::Model,
    /// Terrain: the hypsometric tint instead of the bake's thematic textures
    #[arg(long)]
    no_themes: bool,
    /// Terrain: theme borders stay still from frame to frame
    #[arg(long)]
    no_theme_animation: bool,
    /// Transport to gather from: the encoded one when the bake has it (auto), or the dense
    /// `transport.npy` reference
    #[arg(long, value_enum, default_value_t = TransportChoice::Auto)]
    transport: TransportChoice,
    /// How BC blocks are decoded: by the texture unit (hardware, needs BC support) or by WGSL
    /// decoders over a storage buffer (shader). Default: hardware when the adapter has it
    #[arg(long, value_enum)]
    bc_decode: Option<DecodePath>,
    /// No progress output
    #[arg(short, long)]
    quiet: bool,
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
        emission_scale: cli.emission,
        direct: !cli.no_direct,
        indirect: !cli.no_indirect,
        shadows: !cli.no_shadows,
        soft_shadows: cli.soft,
        horizon_shadows: !cli.no_horizon,
        fog: !cli.no_fog,
        atmosphere: cli.atmosphere,
        themes: !cli.no_themes,
        theme_animation: !cli.no_theme_animation,
        ..Default::default()
    }
}

fn exposure(cli: &Cli) -> Exposure {
    cli.exposure.map_or_else(Exposure::default, Exposure::Fixed)
}

fn player_options(cli: &Cli) -> PlayerOptions {
    PlayerOptions {
        transport: cli.transport,
        decode: cli.bc_decode,
    }
}

fn run(cli: &Cli) -> Result<()> {
    if !cli.headless {
        return relume::player::window::run(relume::player::window::WindowPlan {
            dir: cli.baked_dir.clone(),
            size: cli.size,
            sun: cli.sun,
            camera: cli.camera,
            settings: settings(cli),
            exposure: exposure(cli),
            backend: cli.backend,
            options: player_options(cli),
            lights: cli.light.clone(),
            exit_after: cli.exit_after,
            panel_script: cli.panel_script.clone(),
            panel: !cli.no_panel,
        });
    }
    let gpu = Gpu::new(cli.backend)?;
    if !cli.quiet {
        eprintln!(
            "adapter: {} ({}, {})",
            gpu.info.name, gpu.info.backend, gpu.info.device_type
        );
    }
    let plan = HeadlessPlan {
        dir: cli.baked_dir.clone(),
        out: cli.out.clone(),
        size: cli.size,
        frames: cli.frames,
        sun: cli.sun,
        lights: cli.light.clone(),
        camera: cli.camera,
        settings: settings(cli),
        exposure: exposure(cli),
        options: player_options(cli),
    };
    render_frames(&gpu, &plan)?;
    if !cli.quiet {
        eprintln!(
            "wrote {} frame(s) and frames.json to {}",
            cli.frames,
            cli.out.display()
        );
    }
    Ok(())
}
