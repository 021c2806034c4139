//! `relume-bake reorder|encode|gather`: the compression stages run alone on a baked directory,
//! and the CPU gather from its compressed transport.

use crate::ui::Ui;
use clap::{Args, Subcommand};
use relume::baked::export::StandardLight;
use relume::compress::containers::Container;
use relume::compress::dense::DenseEncoding;
use relume::compress::reorder::{ReorderMethod, ReorderMetric};
use relume::error::exit;
use relume::pipeline::checks::{self, arg};
use relume::pipeline::knobs::{EncodeKnobs, ReorderKnobs};
use relume::pipeline::Stage;
use relume::{Error, Result};
use std::path::PathBuf;

#[derive(Subcommand)]
pub enum CompressCommand {
    /// Reorder a bake's transport matrix (writes permutation.bin; drops later stages)
    Reorder {
        /// Baked directory with transport.npy
        baked_dir: PathBuf,
        /// Greedy passes: 0, 1 (rows) or 2 (rows, then columns; default)
        #[arg(long, value_parser = arg::reorder_passes)]
        passes: Option<u8>,
        /// What the passes compare (default: linear)
        #[arg(long, value_enum)]
        metric: Option<ReorderMetric>,
        /// How each step finds the next row (default: budgeted; bounded: the thesis's exact order, fast; full: the thesis's O(n³))
        #[arg(long, value_enum)]
        method: Option<ReorderMethod>,
    },
    /// Split, map and block-compress a bake's transport (uses permutation.bin when present)
    Encode {
        /// Baked directory with transport.npy
        baked_dir: PathBuf,
        #[command(flatten)]
        knobs: EncodeArgs,
    },
    /// Gather B_ind = S·E from a bake's compressed transport and write it as .npy [channels, n]
    Gather {
        /// Baked directory with an `encode` stage
        baked_dir: PathBuf,
        /// A standard light configuration
        #[arg(long, value_enum, default_value_t = StandardLight::Uniform, conflicts_with = "light_npy")]
        light: StandardLight,
        /// Or the emitted exitance E from an f32 .npy file of shape [channels, n]
        #[arg(long, value_name = "FILE")]
        light_npy: Option<PathBuf>,
        /// Output .npy file
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
    },
}

/// Flags of `encode`: each `None` keeps the pipeline default (`EncodeKnobs::default`).
#[derive(Args)]
pub struct EncodeArgs {
    /// Dense-part encoding (default: bc6h)
    #[arg(long, value_enum)]
    encoding: Option<DenseEncoding>,
    /// Percentage of entries kept exactly in the sidecar (default 1)
    #[arg(long, value_name = "P", value_parser = arg::percent)]
    split_percent: Option<f64>,
    /// Natural-log range of the log mapping (default 25, the radiosity thesis's)
    #[arg(long, value_name = "R", value_parser = arg::positive_f32)]
    log_range: Option<f32>,
    /// Error feedback along rows: true or false
    #[arg(long, value_name = "BOOL")]
    feedback: Option<bool>,
    /// Fill the sidecar's holes (sidecar holds the residual): true or false
    #[arg(long, value_name = "BOOL")]
    fill_holes: Option<bool>,
    /// Largest texture side; bigger matrices are tiled (a multiple of 4; default 8192)
    #[arg(long, value_name = "N")]
    max_texture_size: Option<u32>,
    /// Containers to write (repeat or comma-separate; default dds,ktx2)
    #[arg(long = "container", value_enum, value_delimiter = ',')]
    containers: Vec<Container>,
}

impl EncodeArgs {
    fn knobs(&self) -> Result<EncodeKnobs> {
        let d = EncodeKnobs::default();
        let max_texture_size = match self.max_texture_size {
            Some(m) => checks::texture_size(m)
                .map_err(|e| Error::knob(format!("--max-texture-size: {e}")))?,
            None => d.max_texture_size,
        };
        let mut containers = Vec::new();
        for c in &self.containers {
            if !containers.contains(c) {
                containers.push(*c);
            }
        }
        Ok(EncodeKnobs {
            encoding: self.encoding.unwrap_or(d.encoding),
            split_percent: self.split_percent.unwrap_or(d.split_percent),
            log_range: self.log_range.unwrap_or(d.log_range),
            feedback: self.feedback.unwrap_or(d.feedback),
            fill_holes: self.fill_holes.unwrap_or(d.fill_holes),
            max_texture_size,
            containers: if containers.is_empty() {
                d.containers
            } else {
                containers
            },
        })
    }
}

/// Run one of the compression subcommands.
pub fn run(cmd: &CompressCommand, ui: &Ui, json: bool, quiet: bool) -> Result<i32> {
    let (dir, stage) = match cmd {
        CompressCommand::Reorder {
            baked_dir,
            passes,
            metric,
            method,
        } => {
            let d = ReorderKnobs::default();
            let knobs = ReorderKnobs {
                passes: passes.unwrap_or(d.passes),
                metric: metric.unwrap_or(d.metric),
                method: method.unwrap_or(d.method),
            };
            (baked_dir, Stage::Reorder(knobs))
        }
        CompressCommand::Encode { baked_dir, knobs } => (baked_dir, Stage::Encode(knobs.knobs()?)),
        CompressCommand::Gather {
            baked_dir,
            light,
            light_npy,
            out,
        } => {
            let (ch, n) =
                relume::baked::export::gather(baked_dir, *light, light_npy.as_deref(), out)?;
            if json {
                crate::print_json(
                    &serde_json::json!({"out": out.display().to_string(), "channels": ch, "patches": n}),
                );
            } else if !quiet {
                eprintln!("wrote {} ([{ch}, {n}] f32)", out.display());
            }
            return Ok(exit::OK);
        }
    };
    let report = relume::bake::run_stage_on(dir, stage, ui)?;
    crate::print_stage_report(&report, dir, json, quiet);
    Ok(exit::OK)
}
