//! The infinite-bounce transport in parts. One process factors `I − M` for every channel
//! ([`factor_channels`]: the LU and the f32/f64 check, a third of the flops); then part
//! `index` of `count` solves a contiguous range of the panels of every channel from those
//! factors ([`solve_part`]: the other two thirds, shared out), and [`assemble_infinite`] puts a
//! complete set together into exactly the [`Transport`] that [`crate::radiosity::transport::transport`]
//! returns — the same factors, the same panels, so the same bytes.
//!
//! Finite and Auto bounces are not split: binary doubling multiplies whole matrices, and a
//! single process runs them in the merge.

use crate::error::{Error, Result};
use crate::limits;
use crate::radiosity::transport::infinite::{
    factor_infinite, InfiniteFactor, InfiniteSolver, RowMajor,
};
use crate::radiosity::transport::lu_panels::{panel_count, panel_width, scatter, Panel};
use crate::radiosity::transport::{infinite_bounds, Transport};
use crate::radiosity::TransportMatrix;
use std::ops::Range;

/// One channel's factors, with the solver the check chose and the f32 solve's estimated error.
pub struct ChannelFactors {
    pub factor: InfiniteFactor,
    pub solver: InfiniteSolver,
    pub error: f64,
}

/// One channel's part of an infinite-bounce solve.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelPart {
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

/// Peak working bytes of one part besides F: the factors of one channel (f32; the f64 ones
/// when the check asked for them are twice that) and the part's columns of every channel.
pub fn part_memory(n: usize, channels: usize, index: usize, count: usize) -> u64 {
    let cols = (part_panels(n, index, count).len() * panel_width(n)).min(n);
    (n * n) as u64 * 4 + (channels * cols * n) as u64 * 8
}

fn rho(albedo: &[[f32; 3]], c: usize) -> Vec<f32> {
    albedo.iter().map(|a| a[c]).collect()
}

/// Factor `I − M` of every channel (refusing divergent M), as [`crate::radiosity::transport::transport`]
/// does before its panels.
pub fn factor_channels(
    f: &[f32],
    albedo: &[[f32; 3]],
    solver: InfiniteSolver,
    max_memory: u64,
) -> Result<Vec<ChannelFactors>> {
    let n = albedo.len();
    if f.len() != n * n {
        return Err(Error::Internal(format!(
            "transport factors: {} form factors for {n} patches",
            f.len()
        )));
    }
    (0..channels(albedo))
        .map(|c| {
            let rho = rho(albedo, c);
            let rows = RowMajor { f, rho: &rho };
            infinite_bounds(rows)?;
            let check = |bytes: u64, why: String| limits::check_memory(&why, bytes, max_memory);
            let (factor, solver, error) = factor_infinite(rows, solver, &check)?;
            Ok(ChannelFactors {
                factor,
                solver,
                error,
            })
        })
        .collect()
}

/// Channel `c`'s part `index` of `count` of `S_∞` from that channel's factors.
pub fn solve_part(
    f: &[f32],
    albedo: &[[f32; 3]],
    c: usize,
    factors: &ChannelFactors,
    index: usize,
    count: usize,
) -> Result<ChannelPart> {
    let n = albedo.len();
    if index >= count || c >= channels(albedo) {
        return Err(Error::Internal(format!(
            "transport part {index}/{count} of channel {c}"
        )));
    }
    let rho = rho(albedo, c);
    let panels = factors
        .factor
        .solve_panels(part_panels(n, index, count), RowMajor { f, rho: &rho })?;
    Ok(ChannelPart { panels })
}

/// The transport from the factors and every part, in index order (`parts[i]` = part i of
/// `parts.len()`).
pub fn assemble_infinite(
    f: &[f32],
    albedo: &[[f32; 3]],
    factors: &[(InfiniteSolver, f64)],
    parts: Vec<Vec<ChannelPart>>,
) -> Result<Transport> {
    let count = parts.len();
    let mut a = Assembly::new(albedo, factors, count)?;
    for (i, part) in parts.into_iter().enumerate() {
        a.add(i, part)?;
    }
    a.finish(f, albedo)
}

/// [`assemble_infinite`] one part at a time, so that only one part's columns are held besides S.
pub struct Assembly {
    n: usize,
    channels: usize,
    count: usize,
    added: Vec<bool>,
    solvers: Vec<(InfiniteSolver, f64)>,
    values: Vec<f32>,
}

impl Assembly {
    pub fn new(
        albedo: &[[f32; 3]],
        factors: &[(InfiniteSolver, f64)],
        count: usize,
    ) -> Result<Self> {
        let n = albedo.len();
        let channels = channels(albedo);
        if factors.len() != channels {
            return Err(Error::Internal(format!(
                "{} channel factors for {channels} channels",
                factors.len()
            )));
        }
        Ok(Assembly {
            n,
            channels,
            count,
            added: vec![false; count],
            solvers: factors.to_vec(),
            values: vec![0f32; channels * n * n],
        })
    }

    /// Part `i` (every channel's panels).
    pub fn add(&mut self, i: usize, part: Vec<ChannelPart>) -> Result<()> {
        let (n, count) = (self.n, self.count);
        if i >= count || self.added[i] || part.len() != self.channels {
            return Err(Error::Internal(format!(
                "transport part {i} of {count}: added twice, out of range or with {} channels",
                part.len()
            )));
        }
        for (c, ch) in part.iter().enumerate() {
            let want = part_panels(n, i, count).len();
            if ch.panels.len() != want {
                return Err(Error::Internal(format!(
                    "transport part {i} of {count} holds {} panels of channel {c}, not {want}",
                    ch.panels.len()
                )));
            }
            scatter(&ch.panels, n, &mut self.values[c * n * n..(c + 1) * n * n]);
        }
        self.added[i] = true;
        Ok(())
    }

    /// The transport, once every part is in.
    pub fn finish(self, f: &[f32], albedo: &[[f32; 3]]) -> Result<Transport> {
        if let Some(i) = self.added.iter().position(|a| !a) {
            return Err(Error::Internal(format!(
                "transport part {i} of {} missing",
                self.count
            )));
        }
        let mut bounds = Vec::with_capacity(self.channels);
        for c in 0..self.channels {
            let rho = rho(albedo, c);
            bounds.push(infinite_bounds(RowMajor { f, rho: &rho })?);
        }
        Ok(Transport {
            matrix: TransportMatrix::new(self.channels, self.n, self.values)?,
            bounces: vec![0; self.channels],
            products: 0,
            spectral_bounds: bounds,
            solvers: self.solvers,
        })
    }
}
