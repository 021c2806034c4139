//! Radiosity subcommands: run `voxelize`, `form-factors` or `transport` alone on a baked
//! directory, and `export` patches (JSON) or matrices (.npy).

use clap::{Args, Subcommand, ValueEnum};
use relume::bake::{run_stage_on_with, BakeOptions};
use relume::error::exit;
use relume::pipeline::Stage;
use relume::radiosity::formfactor::Estimator;
use relume::radiosity::patches::Resolution;
use relume::radiosity::stages::{read_patches, FormFactorsKnobs, TransportKnobs, VoxelizeKnobs};
use relume::radiosity::transport::{Bounces, Power};
use relume::radiosity::{FORM_FACTORS_FILE, PATCHES_FILE, TRANSPORT_FILE};
use relume::{Error, Result};
use serde::Serialize;
use std::path::{Path, PathBuf};

#[derive(Subcommand)]
pub enum Command {
    /// Run the `voxelize` stage alone on a baked directory (later stages are dropped)
    Voxelize {
        /// Baked directory of a scene
        baked_dir: PathBuf,
        /// Choose the voxel size so that about this many patches result (default 1000)
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
        target_patches: Option<u32>,
        /// Voxel edge length in scene units
        #[arg(long, value_name = "S", conflicts_with = "target_patches", value_parser = positive)]
        voxel_size: Option<f64>,
        /// Points per patch stored for the runtime's direct light
        #[arg(long, value_name = "K", default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..))]
        samples_per_patch: u32,
        #[command(flatten)]
        budget: Budget,
    },
    /// Run the `form_factors` stage alone on a baked directory (later stages are dropped)
    FormFactors {
        /// Baked directory with patches
        baked_dir: PathBuf,
        /// Estimator
        #[arg(long, value_enum, default_value_t = EstimatorArg::Hemisphere)]
        estimator: EstimatorArg,
        /// Rays per patch (hemisphere, default 4096) or point pairs per patch pair (pairwise, default 16)
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
        samples: Option<u32>,
        /// Seed of the random numbers
        #[arg(long, default_value_t = 0)]
        seed: u64,
        #[command(flatten)]
        budget: Budget,
    },
    /// Run the `transport` stage alone on a baked directory
    Transport {
        /// Baked directory with form factors
        baked_dir: PathBuf,
        /// Bounces: a count k ≥ 1, `inf`, or `auto:TOL` (stop when a bounce adds less than TOL)
        #[arg(long, default_value = "inf", value_parser = parse_bounces)]
        bounces: Bounces,
        /// How finite k is evaluated
        #[arg(long, value_enum, default_value_t = PowerArg::Auto)]
        power: PowerArg,
        #[command(flatten)]
        budget: Budget,
    },
    /// Export patches as JSON, or the form-factor / transport matrix as .npy
    Export {
        /// Baked directory
        baked_dir: PathBuf,
        /// What to export
        #[arg(value_enum)]
        what: ExportWhat,
        /// Output file
        #[arg(long, short)]
        out: PathBuf,
    },
}

#[derive(Args)]
pub struct Budget {
    /// Refuse work whose estimated memory exceeds this (e.g. 512M, 8G; default 75% of RAM)
    #[arg(long, value_name = "SIZE", value_parser = relume::limits::parse_bytes)]
    max_memory: Option<u64>,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum EstimatorArg {
    Hemisphere,
    Pairwise,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum PowerArg {
    Auto,
    Horner,
    Doubling,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum ExportWhat {
    Patches,
    FormFactors,
    Transport,
}

fn positive(s: &str) -> std::result::Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("`{s}` is not a positive number")),
    }
}

fn parse_bounces(s: &str) -> std::result::Result<Bounces, String> {
    let t = s.trim().to_ascii_lowercase();
    if t == "inf" || t == "infinite" {
        return Ok(Bounces::Infinite);
    }
    if let Some(tol) = t.strip_prefix("auto:") {
        return match tol.parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => Ok(Bounces::Auto(v)),
            _ => Err(format!("`{tol}` is not a positive tolerance")),
        };
    }
    match t.parse::<u32>() {
        Ok(k) if k >= 1 => Ok(Bounces::Finite(k)),
        _ => Err(format!(
            "`{s}` is not a bounce count (k ≥ 1, `inf` or `auto:TOL`)"
        )),
    }
}

/// Run a radiosity subcommand.
pub fn run(cmd: &Command, json: bool, quiet: bool, ui: &crate::ui::Ui) -> Result<i32> {
    let (dir, stage, budget) = match cmd {
        Command::Voxelize {
            baked_dir,
            target_patches,
            voxel_size,
            samples_per_patch,
            budget,
        } => {
            let resolution = match (voxel_size, target_patches) {
                (Some(s), _) => Resolution::VoxelSize(*s),
                (None, Some(n)) => Resolution::TargetPatches(*n),
                (None, None) => VoxelizeKnobs::default().resolution,
            };
            let knobs = VoxelizeKnobs {
                resolution,
                samples_per_patch: *samples_per_patch,
            };
            (baked_dir, Stage::Voxelize(knobs), budget)
        }
        Command::FormFactors {
            baked_dir,
            estimator,
            samples,
            seed,
            budget,
        } => {
            let estimator = match estimator {
                EstimatorArg::Hemisphere => Estimator::Hemisphere,
                EstimatorArg::Pairwise => Estimator::Pairwise,
            };
            let knobs = FormFactorsKnobs {
                estimator,
                samples: *samples,
                seed: *seed,
            };
            (baked_dir, Stage::FormFactors(knobs), budget)
        }
        Command::Transport {
            baked_dir,
            bounces,
            power,
            budget,
        } => {
            let power = match power {
                PowerArg::Auto => Power::Auto,
                PowerArg::Horner => Power::Horner,
                PowerArg::Doubling => Power::Doubling,
            };
            let knobs = TransportKnobs {
                bounces: *bounces,
                power,
            };
            (baked_dir, Stage::Transport(knobs), budget)
        }
        Command::Export {
            baked_dir,
            what,
            out,
        } => return export(baked_dir, *what, out, json),
    };
    let mut opts = BakeOptions::default();
    if let Some(m) = budget.max_memory {
        opts.max_memory = m;
    }
    let report = run_stage_on_with(dir, stage, &opts, ui)?;
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).expect("report serialises")
        );
    } else if !quiet {
        for s in &report.stages {
            eprintln!(
                "ran {} on {} in {:.2} s → {}",
                s.stage,
                dir.display(),
                s.seconds,
                s.outputs.join(", ")
            );
        }
    }
    Ok(exit::OK)
}

#[derive(Serialize)]
struct PatchesJson {
    voxel_size: f64,
    origin: [f64; 3],
    grid: [u32; 3],
    patches: Vec<PatchJson>,
}

#[derive(Serialize)]
struct PatchJson {
    id: usize,
    area: f32,
    centroid: [f32; 3],
    normal: [f32; 3],
    axis: &'static str,
    voxel: [u32; 3],
    albedo: [f32; 3],
    emission: [f32; 3],
    objects: Vec<String>,
}

fn export(dir: &Path, what: ExportWhat, out: &Path, json: bool) -> Result<i32> {
    let manifest = relume::baked::Manifest::read(dir)?;
    let file = match what {
        ExportWhat::Patches => PATCHES_FILE,
        ExportWhat::FormFactors => FORM_FACTORS_FILE,
        ExportWhat::Transport => TRANSPORT_FILE,
    };
    if manifest.file(file).is_none() {
        return Err(Error::input(
            dir,
            format!("this bake has no `{file}`; run the stage that writes it first (see `relume-bake inspect`)"),
        ));
    }
    let src = dir.join(file);
    match what {
        ExportWhat::Patches => {
            let set = read_patches(&src)?;
            const AXES: [&str; 6] = ["+x", "-x", "+y", "-y", "+z", "-z"];
            let doc = PatchesJson {
                voxel_size: set.voxel_size,
                origin: set.origin,
                grid: set.dims,
                patches: set
                    .patches
                    .iter()
                    .enumerate()
                    .map(|(id, p)| PatchJson {
                        id,
                        area: p.area,
                        centroid: p.centroid,
                        normal: p.normal,
                        axis: AXES[p.axis as usize % 6],
                        voxel: p.voxel,
                        albedo: p.albedo,
                        emission: p.emission,
                        objects: p
                            .objects
                            .iter()
                            .map(|&o| set.objects.get(o as usize).cloned().unwrap_or_default())
                            .collect(),
                    })
                    .collect(),
            };
            let text = serde_json::to_string_pretty(&doc)
                .map_err(|e| Error::Internal(format!("cannot encode JSON: {e}")))?;
            std::fs::write(out, text).map_err(|e| Error::io(out, "cannot write", e))?;
        }
        ExportWhat::FormFactors | ExportWhat::Transport => {
            let (shape, values) = relume::baked::read_npy_f32(&src)?;
            relume::baked::write_npy_f32(out, &shape, &values)?;
        }
    }
    if json {
        println!("{}", serde_json::json!({"exported": file, "out": out}));
    }
    Ok(exit::OK)
}
