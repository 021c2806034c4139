//! Terrain sweeps (docs/algorithms.md §4, §7): exact (A1) vs accelerated (A2) hard shadows at several map
//! sizes (box-downsampled from the input with [`HeightMap::downsample`]) and sun elevations, and
//! the min/max mipmap build. Reference: the exact traversal's mask; the accelerated traversal
//! must differ on 0 pixels, so its "error" is the count of differing pixels (`sum`), as a
//! fraction (`mean`), and relative to the shadowed pixels (`rms_rel` = sqrt(differing /
//! shadowed)).
//!
//! The soft-shadow methods are compared in [`super::soft_shadows`] on the same maps.

use super::soft_shadows::{soft_shadow_sweep, SoftConfig};
use super::timing::{timed, timed_cpu};
use super::{relative, Column, ErrorStats, Format, Measure, PlotSpec, Setting, Sweep};
use crate::error::{Error, Result};
use crate::heightmap::HeightMap;
use crate::progress::{Progress, Silent};
use crate::terrain::hard::relief::{shadow_mask, HardMethod};
use crate::terrain::{MinMaxMipmap, Sun};

/// What the terrain sweeps run.
#[derive(Clone, Debug, PartialEq)]
pub struct TerrainConfig {
    /// Map sizes (texels along the longer side) to downsample the input to.
    pub sizes: Vec<usize>,
    /// Sun elevations in degrees.
    pub elevations: Vec<f64>,
    /// Sun azimuth in degrees clockwise from north.
    pub azimuth: f64,
    /// The soft-shadow sweep (on the same sizes and azimuth).
    pub soft: SoftConfig,
}

impl TerrainConfig {
    /// Puget Sound at 1K, 2K, 4K; four elevations (minutes: the exact traversal at 4K is slow).
    pub fn full() -> Self {
        TerrainConfig {
            sizes: vec![1024, 2048, 4096],
            elevations: vec![5.0, 15.0, 30.0, 60.0],
            azimuth: 300.0,
            soft: SoftConfig::full(),
        }
    }

    pub fn quick() -> Self {
        TerrainConfig {
            sizes: vec![256, 512],
            elevations: vec![5.0, 30.0],
            azimuth: 300.0,
            soft: SoftConfig::quick(),
        }
    }
}

/// Downsample `map` so that its longer side is about `size` (an integer factor; `size` larger
/// than the map is refused).
pub fn downsample_to(map: &HeightMap, size: usize) -> Result<HeightMap> {
    let longest = map.width.max(map.height);
    if size == 0 || size > longest {
        return Err(Error::knob(format!(
            "study size {size} is not in 1..={longest} (the input is {}x{}; sizes are reached by downsampling)",
            map.width, map.height
        )));
    }
    let factor = (longest as f64 / size as f64).round().max(1.0) as usize;
    Ok(if factor == 1 {
        map.clone()
    } else {
        map.downsample(factor)
    })
}

/// Shadow-mask differences as error statistics (values 0/1; the reference is the exact mask).
fn mask_errors(approx: &[bool], exact: &[bool]) -> ErrorStats {
    let differ = approx.iter().zip(exact).filter(|(a, b)| a != b).count() as f64;
    let shadowed = exact.iter().filter(|s| **s).count() as f64;
    let n = exact.len().max(1) as f64;
    ErrorStats {
        mean: differ / n,
        max: if differ > 0.0 { 1.0 } else { 0.0 },
        rms: (differ / n).sqrt(),
        rms_rel: relative(differ, shadowed),
        sum: Some(differ),
    }
}

/// The terrain sweeps on `map` (the full-resolution input).
pub fn run(map: &HeightMap, cfg: &TerrainConfig, progress: &dyn Progress) -> Result<Vec<Sweep>> {
    let suns = cfg
        .elevations
        .iter()
        .map(|&e| Sun::new(cfg.azimuth, e))
        .collect::<Result<Vec<_>>>()?;
    let mut sizes = cfg.sizes.clone();
    sizes.sort_unstable();
    sizes.dedup();
    let mut maps = Vec::new();
    for &size in &sizes {
        maps.push(downsample_to(map, size)?);
    }
    let mut hard = Sweep {
        name: "terrain_hard_shadows".into(),
        title: "Terrain: hard shadows".into(),
        description: format!(
            "input {}x{} downsampled to {sizes:?} (longer side); sun azimuth {}°, elevations {:?}°",
            map.width, map.height, cfg.azimuth, cfg.elevations
        ),
        reference:
            "the exact traversal (A1) of the same size and elevation; differing pixels must be 0"
                .into(),
        time: "whole shadow mask, wall".into(),
        bytes: "extra memory: the min/max mipmap (accelerated), none (exact)".into(),
        ..Default::default()
    };
    let mut mip_sweep = Sweep {
        name: "terrain_mipmap".into(),
        title: "Terrain: min/max mipmap build".into(),
        description: format!("min/max mipmap of each size {sizes:?}"),
        reference: "none (the mipmap is exact)".into(),
        time: "mipmap build, wall".into(),
        bytes: "mipmap payload (all levels, f32 max + min)".into(),
        ..Default::default()
    };
    progress.begin("study: hard shadows", (maps.len() * suns.len()) as u64);
    let mut with_mips = Vec::new();
    for map in maps {
        let m = &map;
        let size = m.width.max(m.height);
        let pixels = (m.width * m.height) as f64;
        let (mip, build) = timed(|| MinMaxMipmap::build(m));
        let mut row = Setting::new(format!("{}x{}", m.width, m.height), "mipmap")
            .knob("width", m.width)
            .knob("height", m.height);
        row.seconds = build;
        row.bytes = mip.bytes() as u64;
        row.extra.insert("pixels".into(), pixels);
        row.extra.insert("levels".into(), mip.levels.len() as f64);
        mip_sweep.settings.push(row);
        for sun in &suns {
            let el = sun.elevation_deg;
            let (exact, ew, ec) =
                timed_cpu(|| shadow_mask(m, sun, HardMethod::Exact, None, &Silent));
            let (fast, aw, ac) =
                timed_cpu(|| shadow_mask(m, sun, HardMethod::Accelerated, Some(&mip), &Silent));
            let (swept, sw, sc) =
                timed_cpu(|| shadow_mask(m, sun, HardMethod::Sweep, Some(&mip), &Silent));
            let shadowed = exact.iter().filter(|s| **s).count() as f64 / pixels;
            let exact_label = format!("{size} {el}° exact");
            for (method, mask, wall, cpu) in [
                (HardMethod::Exact, &exact, ew, ec),
                (HardMethod::Accelerated, &fast, aw, ac),
                (HardMethod::Sweep, &swept, sw, sc),
            ] {
                let name = method.label();
                let mut s = Setting::new(format!("{size} {el}° {name}"), format!("{name} {el}°"))
                    .default_if(method == HardMethod::default())
                    .knob("width", m.width)
                    .knob("height", m.height)
                    .knob("sun_elevation", el)
                    .knob("sun_azimuth", cfg.azimuth)
                    .knob("method", name);
                s.reference = method == HardMethod::Exact;
                s.baseline = Some(exact_label.clone());
                s.errors
                    .insert("shadow_mask".into(), mask_errors(mask, &exact));
                s.seconds = wall;
                s.bytes = if s.reference { 0 } else { mip.bytes() as u64 };
                for (k, v) in [
                    ("pixels", pixels),
                    ("cpu_seconds", cpu),
                    ("mpixels_per_second", pixels / wall.max(1e-9) / 1e6),
                    ("mpixels_per_cpu_second", pixels / cpu.max(0.01) / 1e6),
                    ("shadowed_fraction", shadowed),
                    ("speedup_wall", ew / wall.max(1e-9)),
                    ("speedup_cpu", ec.max(0.01) / cpu.max(0.01)),
                ] {
                    s.extra.insert(k.into(), v);
                }
                hard.settings.push(s);
            }
            progress.advance(1);
        }
        with_mips.push((map, mip));
    }
    progress.finish();
    // Every row names its own baseline (the exact traversal of its size and elevation).
    hard.columns = vec![
        Column::error(
            "differing pixels",
            "shadow_mask",
            "sum",
            Format::Count,
            false,
        ),
        Column::extra("in shadow", "shadowed_fraction", Format::Percent, false),
        Column::new("time", Measure::Seconds, Format::Time, true),
        Column::extra("Mpx/s (wall)", "mpixels_per_second", Format::Fixed, false),
        Column::extra("speed-up (wall)", "speedup_wall", Format::Fixed, false),
        Column::extra("speed-up (CPU)", "speedup_cpu", Format::Fixed, false),
        Column::new("bytes", Measure::Bytes, Format::Bytes, false),
    ];
    hard.notes.push(
        "Ratios are against the exact traversal of the same size and elevation. CPU time is the whole process's user + system time (steadier than wall time on a shared machine; resolution 10 ms).".into(),
    );
    hard.plots.push(PlotSpec {
        file: "terrain_hard_shadows_time_vs_pixels.png".into(),
        title: "Terrain: hard shadows, time vs map size".into(),
        x: Measure::extra("pixels"),
        y: Measure::Seconds,
        x_label: "pixels".into(),
        y_label: "seconds (whole mask, wall)".into(),
    });
    mip_sweep.baseline = mip_sweep
        .settings
        .first()
        .map(|s| s.label.clone())
        .unwrap_or_default();
    mip_sweep.columns = vec![
        Column::extra("pixels", "pixels", Format::Count, true),
        Column::extra("levels", "levels", Format::Count, false),
        Column::new("bytes", Measure::Bytes, Format::Bytes, true),
        Column::new("build time", Measure::Seconds, Format::Time, true),
    ];
    mip_sweep.plots.push(PlotSpec {
        file: "terrain_mipmap_time_vs_pixels.png".into(),
        title: "Terrain: mipmap build time vs map size".into(),
        x: Measure::extra("pixels"),
        y: Measure::Seconds,
        x_label: "pixels".into(),
        y_label: "seconds (build, wall)".into(),
    });
    let soft = soft_shadow_sweep(&with_mips, cfg.azimuth, &cfg.soft, progress)?;
    Ok(vec![hard, mip_sweep, soft])
}
