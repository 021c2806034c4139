//! Infinite bounces: `S_∞ = (I − M)⁻¹ M = (I − M)⁻¹ − I` (docs/algorithms.md §3), and the dense
//! f32 helpers the transport uses around faer (row-major ↔ column-major copies, the spectral
//! bounds), each parallel over blocks with rayon and independent of the thread count.
//!
//! **The solve.** One LU with partial pivoting (faer) of `I − M` in **f32**, then S by fixed
//! panels of columns ([`crate::radiosity::transport::lu_panels`]: the flops of one GEMM in all, and any set of panels
//! can be solved by another process — `relume-bake run --shard`). It is checked a priori, before
//! any panel: for 32 columns j spread over S, `s_j` solves `(I − M) s_j = m_j`, the residual
//! `r_j = m_j − (I − M) s_j` is summed in f64 and one correction `δ_j = (I − M)⁻¹ r_j` is solved
//! with the same f32 factors. That is one step of iterative refinement on those columns, so
//! `max |δ| / max |s|` estimates the solve's forward error (tested against the f64 LU on the
//! Cornell box and furnaces up to ρ = 0.999). When the estimate is over [`F32_ACCEPT`], the
//! **f64** LU (the reference) solves it instead, after checking its larger memory against the
//! budget. The check depends only on M, so every shard of a bake takes the same decision.
//!
//! Preconditions: M square, non-negative, with spectral radius < 1 (the caller refuses
//! divergent matrices first).

use crate::error::Result;
pub use crate::radiosity::transport::lu_panels::RowMajor;
use crate::radiosity::transport::lu_panels::{panel_count, scatter, Factored, Panel, Real};
use faer::Mat;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// How `Bounces::Infinite` solves `(I − M) S = M`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum InfiniteSolver {
    /// f32 LU when its a-priori error estimate is at most [`F32_ACCEPT`] of the largest
    /// entry, else f64 (the default).
    #[default]
    Auto,
    /// f32 LU with partial pivoting (faer), never refused.
    F32,
    /// f64 LU with partial pivoting (faer): the reference.
    F64,
}

/// The f32 solve is kept when its estimated error is at most this fraction of S's largest entry
/// (a tenth of the 1e-5 the tests hold both solvers to against the f64 reference).
pub const F32_ACCEPT: f64 = 1e-6;

/// Working bytes per matrix entry of the f64 solve besides F and the output: the f64 LU factor
/// (8) and slack (2).
pub const F64_BYTES_PER_ENTRY: u64 = 10;
/// The same for the f32 solve: the f32 LU factor (4) and slack (2).
pub const F32_BYTES_PER_ENTRY: u64 = 6;

/// Rows or columns per parallel block of the dense helpers.
const BLOCK: usize = 64;

/// Columns per chunk of the reductions over columns (fixed, so sums do not depend on the
/// thread count).
const CHUNK: usize = 256;

/// Σ over fixed chunks of columns q of `term(q, acc)` (each chunk's partial sums in f64 over a
/// fresh `acc` of length n), the partials added in chunk order: parallel and deterministic.
fn column_sums(n: usize, cols: usize, term: impl Fn(usize, &mut [f64]) + Sync) -> Vec<f64> {
    let partial: Vec<Vec<f64>> = (0..cols.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut acc = vec![0f64; n];
            for q in c * CHUNK..((c + 1) * CHUNK).min(cols) {
                term(q, &mut acc);
            }
            acc
        })
        .collect();
    let mut out = vec![0f64; n];
    for p in &partial {
        for (o, v) in out.iter_mut().zip(p) {
            *o += v;
        }
    }
    out
}

/// A factored infinite-bounce solve of one channel, in the precision chosen.
pub enum InfiniteFactor {
    F32(Factored<f32>),
    F64(Factored<f64>),
}

impl InfiniteFactor {
    /// Number of panels of this solve.
    pub fn panels(&self) -> usize {
        match self {
            InfiniteFactor::F32(f) => panel_count(f.n()),
            InfiniteFactor::F64(f) => panel_count(f.n()),
        }
    }

    /// The columns of S of panels `range`.
    pub fn solve_panels(&self, range: Range<usize>, m: RowMajor) -> Result<Vec<Panel>> {
        range
            .map(|p| match self {
                InfiniteFactor::F32(f) => f.panel(p, m),
                InfiniteFactor::F64(f) => f.panel(p, m),
            })
            .collect()
    }
}

/// Factor `I − M` with `solver` (f32 first unless F64 is asked for; f64 when the f32 check fails
/// under Auto, after `check_memory(bytes, why)`). Returns the factors, the solver used and the
/// f32 solve's estimated relative error (0 when the f64 LU solved it without an f32 attempt).
pub fn factor_infinite(
    m: RowMajor,
    solver: InfiniteSolver,
    check_memory: &dyn Fn(u64, String) -> Result<()>,
) -> Result<(InfiniteFactor, InfiniteSolver, f64)> {
    let n = m.rho.len();
    let mut estimate = 0.0;
    if solver != InfiniteSolver::F64 {
        let f32_lu = Factored::<f32>::new(m)?;
        let err = error_estimate(&f32_lu, m);
        if solver == InfiniteSolver::F32 || err <= F32_ACCEPT {
            return Ok((InfiniteFactor::F32(f32_lu), InfiniteSolver::F32, err));
        }
        estimate = err;
    }
    let n2 = (n * n) as u64;
    check_memory(
        n2 * F64_BYTES_PER_ENTRY,
        format!(
            "the f64 infinite-bounce solve of {n} patches (the f32 solve's estimated error, \
             {estimate:.1e}, is over {F32_ACCEPT:e}: the spectral radius is close to 1)"
        ),
    )?;
    let f64_lu = Factored::<f64>::new(m)?;
    Ok((InfiniteFactor::F64(f64_lu), InfiniteSolver::F64, estimate))
}

/// S = (I − M)⁻¹ M, row-major, with `solver` (see [`factor_infinite`]).
pub fn infinite(
    m: RowMajor,
    solver: InfiniteSolver,
    check_memory: &dyn Fn(u64, String) -> Result<()>,
) -> Result<(Vec<f32>, InfiniteSolver, f64)> {
    let n = m.rho.len();
    let (lu, used, err) = factor_infinite(m, solver, check_memory)?;
    let mut out = vec![0f32; n * n];
    // Panels in groups, so the columns in flight stay a small part of S.
    let group = 8;
    for g in (0..lu.panels()).step_by(group) {
        let panels = lu.solve_panels(g..(g + group).min(lu.panels()), m)?;
        scatter(&panels, n, &mut out);
    }
    Ok((out, used, err))
}

/// `max |δ| / max |s|` over 32 columns spread over S (module notes): the 32 right-hand sides
/// solved together, the residuals in one pass over the rows of F.
fn error_estimate<T: Real>(lu: &Factored<T>, m: RowMajor) -> f64 {
    let n = lu.n();
    let k = n.min(32);
    let cols: Vec<usize> = (0..k).map(|c| c * n / k).collect();
    // mj[i·k + c] = M(i, cols[c])
    let mj: Vec<f64> = (0..n)
        .flat_map(|i| cols.iter().map(move |&j| (i, j)))
        .map(|(i, j)| m.rho[i] as f64 * m.f_row(i)[j] as f64)
        .collect();
    let s = lu.solve_many(&mj, k);
    // r = m_j − s + M s in f64, by rows.
    let mut r = vec![0f64; n * k];
    r.par_chunks_mut(k).enumerate().for_each(|(i, ri)| {
        let mut acc = vec![0f64; k];
        for (q, &fv) in m.f_row(i).iter().enumerate() {
            if fv != 0.0 {
                for (a, &x) in acc.iter_mut().zip(&s[q * k..(q + 1) * k]) {
                    *a += fv as f64 * x;
                }
            }
        }
        for c in 0..k {
            ri[c] = mj[i * k + c] - s[i * k + c] + m.rho[i] as f64 * acc[c];
        }
    });
    let delta = lu.solve_many(&r, k);
    let fold = |v: &[f64]| v.iter().fold(0f64, |a, x| a.max(x.abs()));
    match fold(&delta) / fold(&s).max(f64::MIN_POSITIVE) {
        e if e.is_finite() => e,
        _ => f64::INFINITY,
    }
}

/// The column-major matrix `f(i, j)` (i, j < n), filled by column blocks in parallel with
/// 64×64 tiles (cache-friendly when `f` reads a row-major array).
pub fn from_fn_tiled(n: usize, f: impl Fn(usize, usize) -> f32 + Sync) -> Mat<f32> {
    let mut out = Mat::<f32>::zeros(n, n);
    out.par_col_chunks_mut(BLOCK)
        .enumerate()
        .for_each(|(b, mut block)| {
            let j0 = b * BLOCK;
            for i0 in (0..n).step_by(BLOCK) {
                for dj in 0..block.ncols() {
                    for i in i0..(i0 + BLOCK).min(n) {
                        block[(i, dj)] = f(i, j0 + dj);
                    }
                }
            }
        });
    out
}

/// The entries of `s` in row-major order, by row blocks in parallel with 64×64 tiles.
pub fn to_row_major(s: &Mat<f32>) -> Vec<f32> {
    let (rows, cols) = (s.nrows(), s.ncols());
    let mut out = vec![0f32; rows * cols];
    out.par_chunks_mut(BLOCK * cols.max(1))
        .enumerate()
        .for_each(|(b, chunk)| {
            let i0 = b * BLOCK;
            let n_rows = chunk.len() / cols.max(1);
            for j0 in (0..cols).step_by(BLOCK) {
                for j in j0..(j0 + BLOCK).min(cols) {
                    let col = &s.col_as_slice(j)[i0..i0 + n_rows];
                    for (di, &v) in col.iter().enumerate() {
                        chunk[di * cols + j] = v;
                    }
                }
            }
        });
    out
}

/// Collatz–Wielandt bounds (lower, upper) on the spectral radius of a non-negative matrix, from
/// at most 64 steps of power iteration started at the all-ones vector, stopping once the
/// bounds are within 1e-7 of each other, or within 1e-3 with the upper one below 0.999, or —
/// when `enough_below` is given — as soon as the upper bound is below it (the first step's
/// bounds are the smallest and largest row sums). Each product by fixed chunks of columns in
/// parallel, summed in f64 in the same order whatever the thread count.
pub fn spectral_bounds(m: &Mat<f32>, enough_below: Option<f64>) -> (f64, f64) {
    let n = m.nrows();
    bounds_by(n, enough_below, |x| {
        column_sums(n, n, |j, acc| {
            let xj = x[j];
            if xj != 0.0 {
                for (yi, &v) in acc.iter_mut().zip(m.col_as_slice(j)) {
                    *yi += v as f64 * xj;
                }
            }
        })
    })
}

/// [`spectral_bounds`] of M given by rows (each product by rows in parallel, each row summed in
/// order: deterministic), without building the column-major M.
pub fn spectral_bounds_rows(m: RowMajor, enough_below: Option<f64>) -> (f64, f64) {
    let n = m.rho.len();
    bounds_by(n, enough_below, |x| {
        (0..n)
            .into_par_iter()
            .map(|i| {
                let s: f64 = m.f_row(i).iter().zip(x).map(|(&f, &v)| f as f64 * v).sum();
                m.rho[i] as f64 * s
            })
            .collect()
    })
}

/// The power iteration of [`spectral_bounds`] with the product `y = M x` given.
fn bounds_by(
    n: usize,
    enough_below: Option<f64>,
    product: impl Fn(&[f64]) -> Vec<f64>,
) -> (f64, f64) {
    let mut x = vec![1f64; n];
    let mut bounds: (f64, f64) = (0.0, f64::INFINITY);
    for _ in 0..64 {
        let y = product(&x);
        let (mut lo, mut hi) = (f64::INFINITY, 0f64);
        for i in 0..n {
            if x[i] > 0.0 {
                let r = y[i] / x[i];
                lo = lo.min(r);
                hi = hi.max(r);
            }
        }
        if lo.is_finite() {
            bounds = (bounds.0.max(lo), bounds.1.min(hi));
            // Converged; or within 0.1 % and the upper bound under 0.999: the caller refuses
            // only a lower bound ≥ 1 − 1e-6, which such a matrix cannot have, and the bounds
            // are otherwise a report.
            let gap = bounds.1 - bounds.0;
            if gap <= 1e-7 * bounds.1
                || (gap <= 1e-3 * bounds.1 && bounds.1 < 0.999)
                || enough_below.is_some_and(|t| bounds.1 < t)
            {
                break;
            }
        }
        let top = y.iter().copied().fold(0.0, f64::max);
        if top <= 0.0 {
            return (0.0, 0.0);
        }
        x = y.into_iter().map(|v| v / top).collect();
    }
    bounds
}
