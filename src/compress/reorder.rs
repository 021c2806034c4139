//! Greedy reordering of a transport matrix (the radiosity thesis §4.2; docs/algorithms.md §3 "Compression" step 1).
//!
//! One pass: compare every pair of rows (or columns) by the sum of absolute differences over all
//! channels; start at position 0 and repeatedly place the most similar remaining row next (ties:
//! the lowest index). The radiosity thesis runs a rows pass, then a columns pass on the result. Each pass's
//! order is applied to rows and columns together (`S' = P S Pᵀ`), so `B' = S' E'` stays exact.
//!
//! Cost: a pass computes all n²/2 pairwise distances of vectors of length `channels·n`
//! (O(channels·n³), blocked for cache, parallel over tiles), then an O(n²) greedy walk. Memory:
//! an n×n f32 distance matrix plus one copy of S.
//!
//! Beyond the thesis, [`ReorderMetric::Log`] compares the log-mapped 8-bit codes (the values the
//! block encoder actually compresses) instead of the raw values, which are dominated by the few
//! large entries that the split removes anyway.

use super::distance::{l1, KCHUNK};
use super::logmap::LogMap;
use crate::radiosity::TransportMatrix;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// What the greedy pass compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum ReorderMetric {
    /// The radiosity thesis's: sum of absolute differences of the raw values.
    #[default]
    Linear,
    /// Sum of absolute differences of the radiosity thesis's 8-bit log codes (per-channel scale = the
    /// channel's largest entry, range e^-25).
    Log,
}

/// How a greedy pass finds each next row: both give the thesis's greedy order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum ReorderMethod {
    /// The thesis's: all n²/2 pairwise distances (O(channels·n³), an n×n matrix and copies of S).
    Full,
    /// The same walk with signature lower bounds ([`super::reorder_bounded`]): no distance
    /// matrix, no copy of S (the columns pass transposes S in place and back). `Linear` only;
    /// with `Log` the pass falls back to `Full`.
    Bounded,
    /// The bounded walk measuring at most [`BUDGET`] exact distances per step (the smallest
    /// bounds): an approximation whose cost does not grow with near-tied rows. The default:
    /// at 8,000 patches 4× faster than `Bounded` and below the encode stage's time, with
    /// compression errors no worse (docs/compression.md).
    #[default]
    Budgeted,
}

/// Exact distances per step of [`ReorderMethod::Budgeted`] (chosen from the sweep of 2, 4, 8
/// in docs/compression.md).
pub const BUDGET: usize = 8;

/// Knobs of [`reorder`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReorderOptions {
    /// 0 (identity), 1 (rows) or 2 (rows, then columns).
    pub passes: u8,
    pub metric: ReorderMetric,
    pub method: ReorderMethod,
}

/// Which vectors a pass compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    Rows,
    Columns,
}

/// The permutation (`perm[k]` = original index at position `k`) after `opts.passes` greedy
/// passes (rows first, then columns). Deterministic for any thread count. With
/// [`ReorderMethod::Bounded`] (and `Linear`) `m` is transposed in place during the columns pass
/// and restored, bit for bit, before this returns.
pub fn reorder(m: &mut TransportMatrix, opts: ReorderOptions) -> Vec<u32> {
    let budget = match opts.method {
        ReorderMethod::Full => None,
        ReorderMethod::Bounded => Some(None),
        ReorderMethod::Budgeted => Some(Some(BUDGET)),
    };
    if let (Some(budget), ReorderMetric::Linear) = (budget, opts.metric) {
        return bounded(m, opts.passes.min(2), budget);
    }
    full(m, opts)
}

fn bounded(m: &mut TransportMatrix, passes: u8, budget: Option<usize>) -> Vec<u32> {
    use super::reorder_bounded::{
        bounded_walk, permute_rows_in_place, transpose_in_place, Vectors,
    };
    let mut perm: Vec<u32> = (0..m.n as u32).collect();
    if passes >= 1 {
        perm = bounded_walk(&Vectors { m, order: None }, budget);
    }
    if passes >= 2 {
        // Columns of P S Pᵀ = rows of (P S)ᵀ, picked in the order perm: permute S's rows and
        // transpose, in place; undo both afterwards (pure moves: S comes back bit for bit).
        permute_rows_in_place(m, &perm, false);
        transpose_in_place(m);
        let order = bounded_walk(
            &Vectors {
                m,
                order: Some(&perm),
            },
            budget,
        );
        transpose_in_place(m);
        permute_rows_in_place(m, &perm, true);
        perm = order.iter().map(|&k| perm[k as usize]).collect();
    }
    perm
}

/// The thesis's passes over the full distance matrix.
fn full(m: &TransportMatrix, opts: ReorderOptions) -> Vec<u32> {
    let mut perm: Vec<u32> = (0..m.n as u32).collect();
    let mut current: Option<TransportMatrix> = None;
    for pass in 0..opts.passes.min(2) {
        let axis = if pass == 0 { Axis::Rows } else { Axis::Columns };
        let src = current.as_ref().unwrap_or(m);
        let order = greedy_pass(src, axis, opts.metric);
        perm = order.iter().map(|&k| perm[k as usize]).collect();
        if pass + 1 < opts.passes.min(2) {
            current = Some(m.permuted(&perm));
        }
    }
    perm
}

/// One greedy pass over rows or columns of `m`: the order of positions.
pub fn greedy_pass(m: &TransportMatrix, axis: Axis, metric: ReorderMetric) -> Vec<u32> {
    let n = m.n;
    if n <= 2 {
        return (0..n as u32).collect();
    }
    let vectors = feature_vectors(m, axis, metric);
    let dist = pairwise_l1(&vectors, n, m.channels * n);
    greedy_walk(&dist, n)
}

/// The vectors a pass compares, one per row (or column), each `channels·n` long, contiguous.
fn feature_vectors(m: &TransportMatrix, axis: Axis, metric: ReorderMetric) -> Vec<f32> {
    let (n, ch) = (m.n, m.channels);
    let maps: Vec<LogMap> = (0..ch)
        .map(|c| LogMap::seed(channel_max(&m.data[c * n * n..(c + 1) * n * n])))
        .collect();
    let feature = |c: usize, v: f32| match metric {
        ReorderMetric::Linear => v,
        ReorderMetric::Log => maps[c].encode(v) as f32,
    };
    let d = ch * n;
    let mut out = vec![0.0f32; n * d];
    out.par_chunks_mut(d).enumerate().for_each(|(k, vec)| {
        for c in 0..ch {
            let dst = &mut vec[c * n..(c + 1) * n];
            match axis {
                Axis::Rows => {
                    for (o, &v) in dst.iter_mut().zip(m.row(c, k)) {
                        *o = feature(c, v);
                    }
                }
                Axis::Columns => {
                    for (i, o) in dst.iter_mut().enumerate() {
                        *o = feature(c, m.get(c, i, k));
                    }
                }
            }
        }
    });
    out
}

fn channel_max(v: &[f32]) -> f32 {
    v.iter().fold(0.0f32, |a, &b| a.max(b))
}

const TILE: usize = 64;

/// All pairwise L1 distances between the `n` vectors of length `d` in `x` (n×n, symmetric,
/// zero diagonal). Blocked: tiles of 64×64 pairs over chunks of 512 coordinates, so both tiles'
/// chunks stay in cache. Each distance is summed in a fixed order (thread-count independent).
pub fn pairwise_l1(x: &[f32], n: usize, d: usize) -> Vec<f32> {
    let tiles = n.div_ceil(TILE);
    let pairs: Vec<(usize, usize)> = (0..tiles)
        .flat_map(|a| (a..tiles).map(move |b| (a, b)))
        .collect();
    let blocks: Vec<Vec<f32>> = pairs
        .par_iter()
        .map(|&(a, b)| {
            let (i0, i1) = (a * TILE, ((a + 1) * TILE).min(n));
            let (j0, j1) = (b * TILE, ((b + 1) * TILE).min(n));
            let mut acc = vec![0.0f32; TILE * TILE];
            let mut k0 = 0;
            while k0 < d {
                let k1 = (k0 + KCHUNK).min(d);
                for i in i0..i1 {
                    let xi = &x[i * d + k0..i * d + k1];
                    let arow = &mut acc[(i - i0) * TILE..(i - i0 + 1) * TILE];
                    for j in j0.max(i + 1)..j1 {
                        arow[j - j0] += l1(xi, &x[j * d + k0..j * d + k1]);
                    }
                }
                k0 = k1;
            }
            // (Each entry is `l1_chunked` of its pair: the same chunks, in the same order.)
            acc
        })
        .collect();
    let mut dist = vec![0.0f32; n * n];
    for (&(a, b), acc) in pairs.iter().zip(&blocks) {
        let (i0, i1) = (a * TILE, ((a + 1) * TILE).min(n));
        let (j0, j1) = (b * TILE, ((b + 1) * TILE).min(n));
        for i in i0..i1 {
            for j in j0.max(i + 1)..j1 {
                let v = acc[(i - i0) * TILE + (j - j0)];
                dist[i * n + j] = v;
                dist[j * n + i] = v;
            }
        }
    }
    dist
}

/// The radiosity thesis's walk: start at 0, repeatedly go to the nearest unvisited vector (ties: lowest
/// index).
fn greedy_walk(dist: &[f32], n: usize) -> Vec<u32> {
    let mut used = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut cur = 0usize;
    used[0] = true;
    order.push(0u32);
    for _ in 1..n {
        let row = &dist[cur * n..(cur + 1) * n];
        let mut best = usize::MAX;
        let mut best_d = f32::INFINITY;
        for (j, &dj) in row.iter().enumerate() {
            if !used[j] && (dj < best_d || best == usize::MAX) {
                best = j;
                best_d = dj;
            }
        }
        used[best] = true;
        order.push(best as u32);
        cur = best;
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compress::distance::l1_chunked;
    use crate::compress::reorder_bounded::l1_concat;

    /// The one summation order: `l1_concat` over channel rows, `l1_chunked` over their
    /// concatenation and every entry of `pairwise_l1` agree bit for bit, also when a chunk spans
    /// two channels (n = 300: chunks of 512 straddle the rows).
    #[test]
    fn every_distance_sums_in_the_same_order() {
        for (n, ch) in [(300usize, 3usize), (1100, 1), (7, 3)] {
            let vecs: Vec<Vec<f32>> = (0..4)
                .map(|v| {
                    (0..ch * n)
                        .map(|k| (((k * 7919 + v * 104729) % 1013) as f32 / 1013.0).powi(3))
                        .collect()
                })
                .collect();
            let flat: Vec<f32> = vecs.concat();
            let all = pairwise_l1(&flat, 4, ch * n);
            for a in 0..4 {
                for b in 0..4 {
                    let (ra, rb): (Vec<&[f32]>, Vec<&[f32]>) =
                        (vecs[a].chunks(n).collect(), vecs[b].chunks(n).collect());
                    let c = l1_concat(&ra, &rb, f32::INFINITY);
                    let want = l1_chunked(&vecs[a], &vecs[b]);
                    assert_eq!(c.to_bits(), want.to_bits(), "n {n} ch {ch}");
                    if a != b {
                        assert_eq!(all[a * 4 + b].to_bits(), want.to_bits(), "n {n} ch {ch}");
                    }
                }
            }
        }
    }

    #[test]
    fn pairwise_matches_brute_force() {
        let n = 150;
        let d = 1100;
        let x: Vec<f32> = (0..n * d)
            .map(|k| ((k * 7919) % 1013) as f32 / 1013.0)
            .collect();
        let dist = pairwise_l1(&x, n, d);
        for i in (0..n).step_by(13) {
            for j in (0..n).step_by(7) {
                let b: f64 = (0..d)
                    .map(|k| (x[i * d + k] as f64 - x[j * d + k] as f64).abs())
                    .sum();
                assert!(
                    (dist[i * n + j] as f64 - b).abs() < 1e-3 * b.max(1.0),
                    "{i} {j}"
                );
            }
        }
    }

    #[test]
    fn greedy_walk_sorts_points_on_a_line() {
        // Scalars in shuffled order: the walk from the first one visits neighbours in order.
        let vals = [0.0f32, 5.0, 1.0, 4.0, 2.0, 3.0];
        let n = vals.len();
        let dist: Vec<f32> = (0..n * n)
            .map(|k| (vals[k / n] - vals[k % n]).abs())
            .collect();
        assert_eq!(greedy_walk(&dist, n), vec![0, 2, 4, 5, 3, 1]);
    }
}
