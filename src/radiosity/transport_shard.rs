//! The infinite-bounce transport in parts: shard `index` of `count` solves a contiguous range of
//! the panels of every channel ([`super::lu_panels`]), and [`assemble_infinite`] puts a complete
//! set together into exactly the [`Transport`] that [`super::transport::transport`] returns — the
//! same factorisation, the same check, the same panels, so the same bytes.
//!
//! Every part factors `I − M` itself (2n³/3 flops per channel, a third of one GEMM); the panels,
//! two thirds of the work, are what the parts share out. Finite and Auto bounces are not split:
//! binary doubling multiplies whole matrices, and a single process runs them in the merge.

use super::infinite::{factor_infinite, InfiniteSolver, RowMajor, F32_BYTES_PER_ENTRY};
use super::lu_panels::{panel_count, panel_width, scatter, Panel};
use super::transport::{infinite_bounds, Transport};
use super::TransportMatrix;
use crate::error::{Error, Result};
use crate::limits;
use std::ops::Range;

/// One channel's part of an infinite-bounce solve.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelPart {
    /// The solver the check chose (the same in every part: it depends on M alone).
    pub solver: InfiniteSolver,
    /// The f32 solve's estimated relative error.
    pub error: f64,
    pub panels: Vec<Panel>,
}

/// Channels the transport models: 1 when every albedo is grey, else 3.
pub fn channels(albedo: &[[f32; 3]]) -> usize {
    if albedo.iter().all(|a| a[0] == a[1] && a[1] == a[2]) {
        1
    } else {
        3
    }
}

/// The panels of part `index` of `count` of an n × n solve.
pub fn part_panels(n: usize, index: usize, count: usize) -> Range<usize> {
    let p = panel_count(n);
    index * p / count..(index + 1) * p / count
}

/// Peak working bytes of one part besides F: the LU factor of one channel, the f64 one if the
/// check asks for it, and the part's columns of every channel.
pub fn part_memory(n: usize, channels: usize, index: usize, count: usize) -> u64 {
    let n2 = (n * n) as u64;
    let cols = (part_panels(n, index, count).len() * panel_width(n)).min(n);
    n2 * F32_BYTES_PER_ENTRY + (channels * cols * n) as u64 * 8
}

/// Part `index` of `count` of `S_∞` for `f` (`[n, n]` row-major F) and per-patch albedo.
pub fn infinite_part(
    f: &[f32],
    albedo: &[[f32; 3]],
    solver: InfiniteSolver,
    max_memory: u64,
    index: usize,
    count: usize,
) -> Result<Vec<ChannelPart>> {
    let n = albedo.len();
    if f.len() != n * n || index >= count {
        return Err(Error::Internal(format!(
            "transport part {index}/{count}: {} form factors for {n} patches",
            f.len()
        )));
    }
    let channels = channels(albedo);
    limits::check_memory(
        &format!("part {index} of {count} of the transport of {n} patches"),
        part_memory(n, channels, index, count),
        max_memory,
    )?;
    (0..channels)
        .map(|c| {
            let rho: Vec<f32> = albedo.iter().map(|a| a[c]).collect();
            let rows = RowMajor { f, rho: &rho };
            infinite_bounds(rows)?;
            let check = |bytes: u64, why: String| limits::check_memory(&why, bytes, max_memory);
            let (lu, solver, error) = factor_infinite(rows, solver, &check)?;
            let panels = lu.solve_panels(part_panels(n, index, count), rows)?;
            Ok(ChannelPart {
                solver,
                error,
                panels,
            })
        })
        .collect()
}

/// The transport from every part, in index order (`parts[i]` = part i of `parts.len()`).
pub fn assemble_infinite(
    f: &[f32],
    albedo: &[[f32; 3]],
    parts: Vec<Vec<ChannelPart>>,
) -> Result<Transport> {
    let n = albedo.len();
    let channels = channels(albedo);
    let mut values = vec![0f32; channels * n * n];
    let mut out = Transport {
        matrix: TransportMatrix::zeros(channels, 0),
        bounces: vec![0; channels],
        products: 0,
        spectral_bounds: Vec::new(),
        solvers: Vec::new(),
    };
    let count = parts.len();
    for c in 0..channels {
        let rho: Vec<f32> = albedo.iter().map(|a| a[c]).collect();
        out.spectral_bounds
            .push(infinite_bounds(RowMajor { f, rho: &rho })?);
        let mut solver = None;
        for (i, part) in parts.iter().enumerate() {
            let ch = part
                .get(c)
                .ok_or_else(|| Error::Internal(format!("transport part {i} has no channel {c}")))?;
            let want = part_panels(n, i, count).len();
            if ch.panels.len() != want {
                return Err(Error::Internal(format!(
                    "transport part {i} of {count} holds {} panels of channel {c}, not {want}",
                    ch.panels.len()
                )));
            }
            match solver {
                None => solver = Some((ch.solver, ch.error)),
                Some(s) if s != (ch.solver, ch.error) => {
                    return Err(Error::Internal(format!(
                        "transport parts disagree on the solver of channel {c}: {s:?} and {:?}",
                        (ch.solver, ch.error)
                    )))
                }
                Some(_) => {}
            }
            scatter(&ch.panels, n, &mut values[c * n * n..(c + 1) * n * n]);
        }
        out.solvers
            .push(solver.unwrap_or((InfiniteSolver::F32, 0.0)));
    }
    out.matrix = TransportMatrix::new(channels, n, values)?;
    Ok(out)
}
