//! `relume-bake reorder|encode|gather`: the compression stages run alone on a baked directory,
//! and the CPU gather from its compressed transport.

use crate::ui::Ui;
use clap::{Args, Subcommand, ValueEnum};
use relume::compress::dense::DenseEncoding;
use relume::compress::reorder::ReorderMetric;
use relume::compress::stages::{Container, EncodeKnobs, ReorderKnobs};
use relume::error::exit;
use relume::pipeline::Stage;
use relume::{Error, Result};
use std::path::{Path, PathBuf};

#[derive(Subcommand)]
pub enum CompressCommand {
    /// Reorder a bake's transport matrix (writes permutation.bin; drops later stages)
    Reorder {
        /// Baked directory with transport.npy
        baked_dir: PathBuf,
        /// Greedy passes: 0, 1 (rows) or 2 (rows, then columns)
        #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(0..=2))]
        passes: u8,
        /// What the passes compare
        #[arg(long, value_enum, default_value_t = MetricArg::Linear)]
        metric: MetricArg,
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
        #[arg(long, value_enum, default_value_t = LightArg::Uniform, conflicts_with = "light_npy")]
        light: LightArg,
        /// Or the emitted exitance E from an f32 .npy file of shape [channels, n]
        #[arg(long, value_name = "FILE")]
        light_npy: Option<PathBuf>,
        /// Output .npy file
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
    },
}

#[derive(Clone, Copy, ValueEnum)]
pub enum MetricArg {
    Linear,
    Log,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum LightArg {
    Uniform,
    Random,
    Half,
    One,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
pub enum EncodingArg {
    Bc1Log,
    Bc4Log,
    Bc6h,
    F16,
    F32,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
pub enum ContainerArg {
    Dds,
    Ktx2,
}

#[derive(Args)]
pub struct EncodeArgs {
    /// Dense-part encoding (default: the pipeline default, see README)
    #[arg(long, value_enum)]
    encoding: Option<EncodingArg>,
    /// Percentage of entries kept exactly in the sidecar
    #[arg(long, value_name = "P", value_parser = parse_percent)]
    split_percent: Option<f64>,
    /// Natural-log range of the log mapping (the seed's 25)
    #[arg(long, value_name = "R", value_parser = parse_positive)]
    log_range: Option<f32>,
    /// Error feedback along rows: true or false
    #[arg(long, value_name = "BOOL")]
    feedback: Option<bool>,
    /// Fill the sidecar's holes (sidecar holds the residual): true or false
    #[arg(long, value_name = "BOOL")]
    fill_holes: Option<bool>,
    /// Largest texture side; bigger matrices are tiled (a multiple of 4)
    #[arg(long, value_name = "N")]
    max_texture_size: Option<u32>,
    /// Containers to write (repeat or comma-separate)
    #[arg(long = "container", value_enum, value_delimiter = ',')]
    containers: Vec<ContainerArg>,
}

fn parse_percent(s: &str) -> std::result::Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if (0.0..=100.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{v} is not a percentage in [0, 100]"))
    }
}

fn parse_positive(s: &str) -> std::result::Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("{v} must be a positive number"))
    }
}

impl EncodeArgs {
    fn knobs(&self) -> Result<EncodeKnobs> {
        let mut k = EncodeKnobs::default();
        if let Some(e) = self.encoding {
            k.encoding = match e {
                EncodingArg::Bc1Log => DenseEncoding::Bc1Log,
                EncodingArg::Bc4Log => DenseEncoding::Bc4Log,
                EncodingArg::Bc6h => DenseEncoding::Bc6h,
                EncodingArg::F16 => DenseEncoding::F16,
                EncodingArg::F32 => DenseEncoding::F32,
            };
        }
        if let Some(p) = self.split_percent {
            k.split_percent = p;
        }
        if let Some(r) = self.log_range {
            k.log_range = r;
        }
        if let Some(f) = self.feedback {
            k.feedback = f;
        }
        if let Some(f) = self.fill_holes {
            k.fill_holes = f;
        }
        if let Some(m) = self.max_texture_size {
            if m < 4 || m % 4 != 0 {
                return Err(Error::knob(format!(
                    "--max-texture-size {m} must be a positive multiple of 4"
                )));
            }
            k.max_texture_size = m;
        }
        if !self.containers.is_empty() {
            let mut cs = Vec::new();
            for c in &self.containers {
                let c = match c {
                    ContainerArg::Dds => Container::Dds,
                    ContainerArg::Ktx2 => Container::Ktx2,
                };
                if !cs.contains(&c) {
                    cs.push(c);
                }
            }
            k.containers = cs;
        }
        Ok(k)
    }
}

/// Run one of the compression subcommands.
pub fn run(cmd: &CompressCommand, ui: &Ui, json: bool, quiet: bool) -> Result<i32> {
    let (dir, stage) = match cmd {
        CompressCommand::Reorder {
            baked_dir,
            passes,
            metric,
        } => (
            baked_dir,
            Stage::Reorder(ReorderKnobs {
                passes: *passes,
                metric: match metric {
                    MetricArg::Linear => ReorderMetric::Linear,
                    MetricArg::Log => ReorderMetric::Log,
                },
            }),
        ),
        CompressCommand::Encode { baked_dir, knobs } => (baked_dir, Stage::Encode(knobs.knobs()?)),
        CompressCommand::Gather {
            baked_dir,
            light,
            light_npy,
            out,
        } => return gather(baked_dir, *light, light_npy.as_deref(), out, json, quiet),
    };
    let report = relume::bake::run_stage_on(dir, stage, ui)?;
    if json {
        crate::print_json(&report);
    } else if !quiet {
        for s in &report.stages {
            eprintln!("{} on {} ({:.2} s)", s.stage, dir.display(), s.seconds);
            for (k, v) in &s.report {
                eprintln!("  {k:<28} {v}");
            }
        }
    }
    Ok(exit::OK)
}

fn gather(
    dir: &Path,
    light: LightArg,
    light_npy: Option<&Path>,
    out: &Path,
    json: bool,
    quiet: bool,
) -> Result<i32> {
    let enc = relume::compress::stages::read_encoded(dir)?;
    let (ch, n) = (enc.dense.channels, enc.dense.n);
    let e = match light_npy {
        Some(p) => {
            let (shape, data) = relume::baked::read_npy_f32(p)?;
            if shape != [ch as u64, n as u64] && !(ch == 1 && shape == [n as u64]) {
                return Err(Error::input(
                    p,
                    format!("light has shape {shape:?}; this bake needs [{ch}, {n}]"),
                ));
            }
            data
        }
        None => {
            let name = match light {
                LightArg::Uniform => "uniform",
                LightArg::Random => "random",
                LightArg::Half => "half",
                LightArg::One => "one",
            };
            relume::compress::report::standard_lights(ch, n)
                .into_iter()
                .find(|(k, _)| k == name)
                .map(|(_, v)| v)
                .expect("standard light exists")
        }
    };
    let b = relume::compress::gather(&enc, &e);
    relume::baked::write_npy_f32(out, &[ch as u64, n as u64], &b)?;
    if json {
        crate::print_json(
            &serde_json::json!({"out": out.display().to_string(), "channels": ch, "patches": n}),
        );
    } else if !quiet {
        eprintln!("wrote {} ([{ch}, {n}] f32)", out.display());
    }
    Ok(exit::OK)
}
