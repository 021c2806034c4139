//! `relume-player`: renders baked directories with wgpu (not yet implemented beyond `--help`).

use clap::Parser;

#[derive(Parser)]
#[command(
    name = "relume-player",
    version,
    about = "Render baked relume scenes and terrain with wgpu (coming: see issue 'relume-player')"
)]
struct Cli {
    /// Baked directory to render
    baked_dir: Option<std::path::PathBuf>,
}

fn main() {
    let cli = Cli::parse();
    if cli.baked_dir.is_some() {
        eprintln!("error: rendering is not yet supported by this relume-player build");
        std::process::exit(relume::error::exit::UNSUPPORTED);
    }
    eprintln!("relume-player: give a baked directory (see --help)");
    std::process::exit(relume::error::exit::USAGE);
}
