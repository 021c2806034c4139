//! `horizon_maps.npy` and `horizon_directions.npy`: the horizon maps of a height-map bake,
//! written by `horizon_maps` (docs/baked-format.md).
//!
//! - `horizon_maps.npy`: u16 `[N, H, W]`, plane k the horizon angle of every texel toward
//!   direction k, quantised as `angle = −90° + v·180°/65535` ([`crate::terrain::horizon::map`]).
//! - `horizon_directions.npy`: i32 `[N, 2]`, direction k's texel step (a columns east, b rows
//!   south); its azimuth follows from the step and the cell size. Sorted by azimuth.
//!
//! The planet radius the angles were computed for is the stage record's `planet_radius_m`
//! (0 = flat ground).

use super::{npy, BakeTransaction, Manifest};
use crate::error::{Error, Result};
use crate::terrain::horizon::map::HorizonMap;
use crate::terrain::horizon::Direction;
use std::path::Path;

/// File name of the angle planes.
pub const FILE: &str = "horizon_maps.npy";
/// File name of the directions.
pub const DIRECTIONS: &str = "horizon_directions.npy";
/// The stage that writes them.
pub const STAGE: &str = "horizon_maps";

/// Write the horizon map into a bake.
pub fn write(txn: &mut BakeTransaction, hm: &HorizonMap) -> Result<()> {
    let n = hm.directions.len() as u64;
    let steps: Vec<i32> = hm
        .directions
        .iter()
        .flat_map(|d| [d.a as i32, d.b as i32])
        .collect();
    txn.write_with(DIRECTIONS, |p| npy::write_npy(p, &[n, 2], &steps))?;
    let shape = [n, hm.height as u64, hm.width as u64];
    let values = hm.angles.iter().flat_map(|p| p.iter().copied());
    txn.write_with(FILE, |p| npy::write_npy_iter(p, &shape, values))
}

/// Read the horizon map of the bake in `dir` for a `width`×`height` map of `cell_size`-metre
/// cells, checking the two files against each other and against the map.
pub fn read(
    dir: &Path,
    manifest: &Manifest,
    (width, height): (usize, usize),
    cell_size: [f64; 2],
) -> Result<HorizonMap> {
    let dpath = dir.join(DIRECTIONS);
    let (dshape, steps) = npy::read_npy::<i32>(&dpath)?;
    let n = match dshape.as_slice() {
        [n, 2] if (1..=360).contains(n) => *n as usize,
        _ => {
            return Err(Error::input(
                &dpath,
                format!("expected [N, 2] directions with N in 1..=360, found shape {dshape:?}"),
            ))
        }
    };
    let mut directions = Vec::with_capacity(n);
    for s in steps.chunks_exact(2) {
        let (a, b) = (s[0] as i64, s[1] as i64);
        if (a, b) == (0, 0) || a.abs() > 1024 || b.abs() > 1024 {
            return Err(Error::input(
                &dpath,
                format!("direction ({a}, {b}) is not a texel step (|a|, |b| ≤ 1024, not both 0)"),
            ));
        }
        directions.push(Direction::new(a, b, cell_size));
    }
    if directions
        .windows(2)
        .any(|p| p[0].azimuth_deg >= p[1].azimuth_deg)
    {
        return Err(Error::input(
            &dpath,
            "directions are not sorted by strictly increasing azimuth",
        ));
    }
    let path = dir.join(FILE);
    let (shape, values) = npy::read_npy::<u16>(&path)?;
    if shape != [n as u64, height as u64, width as u64] {
        return Err(Error::input(
            &path,
            format!(
                "expected [{n}, {height}, {width}] ({n} directions of a {width}x{height} map), \
                 found shape {shape:?}"
            ),
        ));
    }
    let plane = width * height;
    let angles = values
        .chunks_exact(plane.max(1))
        .map(|c| c.to_vec())
        .collect();
    let radius = manifest
        .stage(STAGE)
        .and_then(|r| r.report.get("planet_radius_m").copied())
        .filter(|&r| r > 0.0);
    Ok(HorizonMap {
        width,
        height,
        directions,
        angles,
        planet_radius: radius,
    })
}
