//! The thesis's greedy walk without the n×n distance matrix: the same order, found with lower
//! bounds (`ReorderMethod::Bounded`, the default).
//!
//! Each step of the greedy walk needs the remaining vector nearest (L1) to the current one. A
//! vector's *signature* is its sums over groups of coordinates per channel; since
//! `|Σ_g a − Σ_g b| ≤ Σ_g |a − b|`, the L1 distance of two signatures is a lower bound of the
//! distance of the vectors. A step bounds every remaining vector with the `COARSE` signature
//! (O(n·COARSE)), takes the exact distance of the smallest bound, then visits the others whose
//! bound does not exceed the best exact distance, nearest bound first: each is re-bounded with
//! the `FINE` signature and measured exactly only if that bound does not exclude it either. No
//! vector it skips can be nearer. The exact distances are
//! computed exactly as `super::reorder::pairwise_l1` computes them (chunks of 512
//! coordinates, eight accumulators), and ties go to the lowest index, so the permutation is the
//! thesis's greedy one, bit for bit (tested).
//!
//! Cost: O(n²·COARSE·channels) for the coarse bounds, O(FINE·channels) per candidate and
//! O(channels·n) per exact evaluation (a few per step on transport matrices, whose neighbouring
//! rows are similar), instead of O(channels·n³). Memory: the signatures (n·FINE·channels f64)
//! and two scratch vectors; the
//! columns pass transposes S in place and back (no second copy of S).
//!
//! Precondition: the features are the raw (non-negative or not) f32 values of S (`Linear`); the
//! `Log` metric uses [`super::reorder`]'s feature vectors.

use super::distance::{l1, KCHUNK};
use crate::radiosity::TransportMatrix;
use rayon::prelude::*;

/// Signature groups per channel: the coarse signature bounds every remaining vector each step;
/// the fine one (each coarse group split into `FINE / COARSE`) re-bounds the few candidates the
/// coarse bound cannot exclude, before any exact distance.
pub const COARSE: usize = 32;
pub const FINE: usize = 512;

/// How a pass reads vector `k`: row `order[k]` of the matrix as stored (pass 1: rows of S;
/// pass 2: rows of the transposed, row-permuted S, i.e. columns of P S Pᵀ). `None`: the
/// identity.
pub struct Vectors<'a> {
    pub m: &'a TransportMatrix,
    pub order: Option<&'a [u32]>,
}

impl Vectors<'_> {
    fn row_of(&self, k: usize) -> usize {
        self.order.map_or(k, |o| o[k] as usize)
    }

    /// The channel rows of vector `k` (its feature vector is their concatenation).
    fn rows(&self, k: usize) -> Vec<&[f32]> {
        let r = self.row_of(k);
        (0..self.m.channels).map(|c| self.m.row(c, r)).collect()
    }

    /// Sums of vector `k` over `FINE` consecutive groups of each channel (any partition of the
    /// coordinates gives a bound).
    fn signature(&self, k: usize, out: &mut [f64]) {
        let per = self.m.n.div_ceil(FINE).max(1);
        out.iter_mut().for_each(|v| *v = 0.0);
        for (c, row) in self.rows(k).into_iter().enumerate() {
            for (b, chunk) in row.chunks(per).enumerate() {
                out[c * FINE + b] = chunk.iter().map(|&v| v as f64).sum();
            }
        }
    }
}

/// `l1_chunked` of the concatenations of `a` and `b` (channel rows of equal length), without
/// building them: chunks of `KCHUNK` that span two rows are copied to a small buffer. Stops
/// early with a value above `limit` once the running sum exceeds it (every chunk adds ≥ 0, so
/// the full sum would too); otherwise the value is exactly `l1_chunked`'s.
pub(crate) fn l1_concat(a: &[&[f32]], b: &[&[f32]], limit: f32) -> f32 {
    let n = a[0].len();
    let d = n * a.len();
    let mut acc = 0.0f32;
    let (mut ba, mut bb) = ([0.0f32; KCHUNK], [0.0f32; KCHUNK]);
    let mut t0 = 0;
    while t0 < d {
        let t1 = (t0 + KCHUNK).min(d);
        let (c0, c1) = (t0 / n, (t1 - 1) / n);
        if c0 == c1 {
            let (i0, i1) = (t0 - c0 * n, t1 - c0 * n);
            acc += l1(&a[c0][i0..i1], &b[c0][i0..i1]);
        } else {
            for (k, t) in (t0..t1).enumerate() {
                ba[k] = a[t / n][t % n];
                bb[k] = b[t / n][t % n];
            }
            acc += l1(&ba[..t1 - t0], &bb[..t1 - t0]);
        }
        if acc > limit {
            return acc;
        }
        t0 = t1;
    }
    acc
}

fn l1_f64(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum()
}

/// The greedy walk (start at 0, always the nearest remaining vector, ties to the lowest index).
/// With `budget = Some(k)` a step measures at most `k` exact distances (the candidates with
/// the smallest bounds) and takes the nearest of those: an approximation of the walk whose cost
/// no longer depends on how many rows are near-ties.
pub fn bounded_walk(v: &Vectors, budget: Option<usize>) -> Vec<u32> {
    let (n, ch) = (v.m.n, v.m.channels);
    if n <= 2 {
        return (0..n as u32).collect();
    }
    let (sf, sc) = (ch * FINE, ch * COARSE);
    let mut fine = vec![0.0f64; n * sf];
    fine.par_chunks_mut(sf)
        .enumerate()
        .for_each(|(k, out)| v.signature(k, out));
    let group = FINE / COARSE;
    // Coarse sums in f32 (twice the SIMD width for the n² bounds); their rounding, below 1e-6
    // relative, is covered by `coarse_shrink`.
    let coarse: Vec<f32> = fine
        .chunks(group)
        .map(|g| g.iter().sum::<f64>() as f32)
        .collect();
    // Relative rounding of an f32 distance summed as `l1_chunked` does: each of the eight
    // accumulators of a chunk adds 64 terms, the chunk sums add ch·n/512 more. A bound is used
    // only after shrinking it by four times that.
    let d = ch * n;
    let gamma = ((64 + d / 512 + 16) as f64) * f32::EPSILON as f64;
    let shrink = 1.0 - 4.0 * gamma;
    let coarse_shrink = shrink - 1e-4;
    let mut remaining: Vec<u32> = (1..n as u32).collect();
    let mut order = Vec::with_capacity(n);
    order.push(0u32);
    let mut lbs: Vec<f64> = Vec::with_capacity(n);
    let mut cur = 0usize;
    while !remaining.is_empty() {
        let cur_rows = v.rows(cur);
        let (cc, cf) = (
            &coarse[cur * sc..(cur + 1) * sc],
            &fine[cur * sf..(cur + 1) * sf],
        );
        remaining
            .par_iter()
            .with_min_len(1024)
            .map(|&r| {
                let rc = &coarse[r as usize * sc..(r as usize + 1) * sc];
                l1(cc, rc) as f64 * coarse_shrink
            })
            .collect_into_vec(&mut lbs);
        let exact = |r: usize, limit: f32| l1_concat(&cur_rows, &v.rows(r), limit);
        // An upper bound first: the exact distance of the smallest coarse bound.
        let first = (0..lbs.len())
            .min_by(|&a, &b| lbs[a].total_cmp(&lbs[b]))
            .unwrap();
        let (mut best, mut best_d) = (first, exact(remaining[first] as usize, f32::INFINITY));
        // Everything else that may be as near, nearest bound first.
        let mut todo: Vec<usize> = (0..lbs.len())
            .filter(|&k| k != first && lbs[k] <= best_d as f64)
            .collect();
        todo.sort_by(|&a, &b| lbs[a].total_cmp(&lbs[b]).then(a.cmp(&b)));
        let mut measured = 1;
        for k in todo {
            if lbs[k] > best_d as f64 || budget.is_some_and(|b| measured >= b) {
                break;
            }
            let r = remaining[k] as usize;
            let lb = l1_f64(cf, &fine[r * sf..(r + 1) * sf]) * shrink;
            if lb > best_d as f64 {
                continue;
            }
            measured += 1;
            let dist = exact(r, best_d);
            if dist < best_d || (dist == best_d && r < remaining[best] as usize) {
                best = k;
                best_d = dist;
            }
        }
        let next = remaining.remove(best);
        order.push(next);
        cur = next as usize;
    }
    order
}

/// Move rows so that row `k` becomes old row `perm[k]` (every channel; `inverse` undoes it).
pub fn permute_rows_in_place(m: &mut TransportMatrix, perm: &[u32], inverse: bool) {
    let n = m.n;
    let mut tmp = vec![0.0f32; n];
    // Row k receives row src[k].
    let src: Vec<usize> = if inverse {
        let mut inv = vec![0usize; n];
        for (k, &p) in perm.iter().enumerate() {
            inv[p as usize] = k;
        }
        inv
    } else {
        perm.iter().map(|&p| p as usize).collect()
    };
    for c in 0..m.channels {
        let plane = &mut m.data[c * n * n..(c + 1) * n * n];
        let mut done = vec![false; n];
        for start in 0..n {
            if done[start] {
                continue;
            }
            // Follow the cycle through `start`.
            tmp.copy_from_slice(&plane[start * n..(start + 1) * n]);
            let mut k = start;
            loop {
                done[k] = true;
                let from = src[k];
                if from == start {
                    plane[k * n..(k + 1) * n].copy_from_slice(&tmp);
                    break;
                }
                plane.copy_within(from * n..(from + 1) * n, k * n);
                k = from;
            }
        }
    }
}

/// `P S Pᵀ` in place: entry (k, l) becomes old entry (perm[k], perm[l]), what
/// [`TransportMatrix::permuted`] returns, without the copy (one row of scratch per thread);
/// `inverse` undoes it. Pure moves: undone, S comes back bit for bit.
pub fn permute_symmetric_in_place(m: &mut TransportMatrix, perm: &[u32], inverse: bool) {
    use rayon::prelude::*;
    let n = m.n;
    assert_eq!(perm.len(), n, "permutation length");
    let columns = |m: &mut TransportMatrix| {
        m.data.par_chunks_mut(n.max(1)).for_each_init(
            || vec![0.0f32; n],
            |tmp, row| {
                tmp.copy_from_slice(row);
                for (l, &p) in perm.iter().enumerate() {
                    if inverse {
                        row[p as usize] = tmp[l];
                    } else {
                        row[l] = tmp[p as usize];
                    }
                }
            },
        )
    };
    if inverse {
        columns(m);
        permute_rows_in_place(m, perm, true);
    } else {
        permute_rows_in_place(m, perm, false);
        columns(m);
    }
}

/// Transpose every channel of a square matrix in place (blocked; exact).
pub fn transpose_in_place(m: &mut TransportMatrix) {
    let n = m.n;
    const T: usize = 32;
    for c in 0..m.channels {
        let plane = &mut m.data[c * n * n..(c + 1) * n * n];
        for bi in (0..n).step_by(T) {
            for bj in (bi..n).step_by(T) {
                for i in bi..(bi + T).min(n) {
                    let j0 = if bi == bj { i + 1 } else { bj };
                    for j in j0..(bj + T).min(n) {
                        plane.swap(i * n + j, j * n + i);
                    }
                }
            }
        }
    }
}
