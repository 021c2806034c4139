//! Infinite bounces: `S_∞ = (I − M)⁻¹ M = (I − M)⁻¹ − I` (docs/algorithms.md §3), and the dense
//! f32 helpers the transport uses around faer (row-major ↔ column-major copies, the spectral
//! bounds), each parallel over blocks with rayon and independent of the thread count.
//!
//! **The solve.** One LU with partial pivoting (faer) of `I − M` in **f32**, then its inverse
//! minus I (4/3 n³ flops after the LU's 2/3 n³, against 2n³ for a solve with n right-hand
//! sides; the diagonal, where subtracting I would cost precision, is computed as
//! `Σ_q (I − M)⁻¹(i, q) M(q, i)` in f64), checked a posteriori: for 32 columns spread over S, the residual
//! `r_j = m_j − (I − M) s_j` in f64 and one correction `δ_j = (I − M)⁻¹ r_j` with the same f32
//! factors. That is one step of iterative refinement on those columns, so `max |δ| / max |S|`
//! estimates the solve's forward error (tested against the f64 LU: within 3x on the Cornell
//! box and furnaces up to ρ = 0.999). When the estimate is over [`F32_ACCEPT`], the **f64** LU
//! (the reference) solves it instead, after checking its larger memory against the budget.
//!
//! Preconditions: M square, non-negative, with spectral radius < 1 (the caller refuses
//! divergent matrices first).

use crate::error::{Error, Result};
use faer::linalg::solvers::{DenseSolveCore, Solve};
use faer::Mat;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// How `Bounces::Infinite` solves `(I − M) S = M`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum InfiniteSolver {
    /// f32 LU when its a-posteriori error estimate is at most [`F32_ACCEPT`] of the largest
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

/// Working bytes per matrix entry of the f64 solve: M in f32 and, while faer solves, the f64 LU
/// factor, the f64 solution and faer's f64 scratch, 28 bytes per entry, plus 2 of slack (33
/// and 34 measured, peak RSS less the form factors and the output, on 3- and 1-channel bakes of
/// about 4,000 patches).
pub const F64_BYTES_PER_ENTRY: u64 = 30;
/// The same for the f32 solve: M, I − M, its LU factor and the inverse (16), plus 2 of slack.
pub const F32_BYTES_PER_ENTRY: u64 = 18;

/// Rows or columns per parallel block of the dense helpers.
const BLOCK: usize = 64;

/// M in row-major order as the transport has it: `M(q, i) = rho[q] · f[q·n + i]`.
#[derive(Clone, Copy)]
pub struct RowMajor<'a> {
    pub f: &'a [f32],
    pub rho: &'a [f32],
}

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

/// S = (I − M)⁻¹ M with `solver`; `check_memory(bytes, why)` is called before the f64 solve
/// allocates. Returns S, the solver used and the f32 solve's estimated relative error (0 when
/// the f64 LU solved it without an f32 attempt).
pub fn infinite(
    m: &Mat<f32>,
    rows: RowMajor,
    solver: InfiniteSolver,
    check_memory: &dyn Fn(u64, String) -> Result<()>,
) -> Result<(Mat<f32>, InfiniteSolver, f64)> {
    let mut estimate = 0.0;
    if solver != InfiniteSolver::F64 {
        let (s, err) = infinite_f32(m, rows)?;
        if solver == InfiniteSolver::F32 || err <= F32_ACCEPT {
            return Ok((s, InfiniteSolver::F32, err));
        }
        estimate = err;
    }
    let n2 = (m.nrows() * m.nrows()) as u64;
    check_memory(
        n2 * F64_BYTES_PER_ENTRY,
        format!(
            "the f64 infinite-bounce solve of {} patches (the f32 solve's estimated error, \
             {estimate:.1e}, is over {F32_ACCEPT:e}: the spectral radius is close to 1)",
            m.nrows()
        ),
    )?;
    Ok((infinite_f64(m)?, InfiniteSolver::F64, estimate))
}

/// Refuse a factorisation with a zero or non-finite pivot (|U_ii| over the diagonal).
fn check_pivots(diag: impl Iterator<Item = f64>) -> Result<()> {
    let (mut lo, mut hi) = (f64::INFINITY, 0f64);
    for d in diag {
        let d = d.abs();
        lo = lo.min(d);
        hi = hi.max(d);
    }
    if !(lo.is_finite() && hi.is_finite()) || lo <= 1e-12 * hi.max(1.0) {
        return Err(Error::knob(format!(
            "transport: I − diag(albedo)·F is singular (smallest LU pivot {lo:e}): infinite bounces diverge; use `bounces: Finite(k)`"
        )));
    }
    Ok(())
}

fn non_finite() -> Error {
    Error::knob(
        "transport: the infinite-bounce solve produced a non-finite value; use `bounces: Finite(k)`",
    )
}

/// `(I − M)⁻¹ M` by LU with partial pivoting in f64: the reference.
pub fn infinite_f64(m: &Mat<f32>) -> Result<Mat<f32>> {
    let n = m.nrows();
    let a = Mat::<f64>::from_fn(n, n, |i, j| f64::from(i == j) - m[(i, j)] as f64);
    let lu = a.partial_piv_lu();
    drop(a);
    let u = lu.U();
    check_pivots((0..n).map(|i| u[(i, i)]))?;
    let mut x = Mat::<f64>::from_fn(n, n, |i, j| m[(i, j)] as f64);
    lu.solve_in_place(x.as_mut());
    let mut s = Mat::<f32>::zeros(n, n);
    s.par_col_iter_mut().enumerate().try_for_each(|(j, col)| {
        let src = x.col_as_slice(j);
        for (d, &v) in col
            .try_as_col_major_mut()
            .unwrap()
            .as_slice_mut()
            .iter_mut()
            .zip(src)
        {
            if !v.is_finite() {
                return Err(non_finite());
            }
            *d = v.max(0.0) as f32; // rounding noise around exact zeros
        }
        Ok(())
    })?;
    Ok(s)
}

/// `(I − M)⁻¹ M` by LU with partial pivoting in f32, and its estimated relative error (module
/// notes).
pub fn infinite_f32(m: &Mat<f32>, rows: RowMajor) -> Result<(Mat<f32>, f64)> {
    let n = m.nrows();
    let mut a = m.clone();
    a.par_col_iter_mut().enumerate().for_each(|(j, col)| {
        let c = col.try_as_col_major_mut().unwrap().as_slice_mut();
        c.iter_mut().for_each(|v| *v = -*v);
        c[j] += 1.0;
    });
    let lu = a.partial_piv_lu();
    drop(a);
    let u = lu.U();
    check_pivots((0..n).map(|i| u[(i, i)] as f64))?;
    let mut s = lu.inverse();
    // Off the diagonal S = (I − M)⁻¹; on it, (I − M)⁻¹ − I would keep only f32's absolute
    // precision near 1: S_ii = Σ_q (I − M)⁻¹(i, q) M(q, i) instead, in f64 (both operands
    // read contiguously: columns of the inverse, rows of M).
    let diag = column_sums(n, n, |q, acc| {
        let (col, rq) = (s.col_as_slice(q), rows.rho[q] as f64);
        let fq = &rows.f[q * n..(q + 1) * n];
        for ((a, &v), &fv) in acc.iter_mut().zip(col).zip(fq) {
            *a += v as f64 * rq * fv as f64;
        }
    });
    for (i, d) in diag.into_iter().enumerate() {
        s[(i, i)] = d as f32;
    }
    // The largest |S| and the non-finite check, by columns.
    let top = (0..n)
        .into_par_iter()
        .map(|j| {
            s.col_as_slice(j)
                .iter()
                .try_fold(0f64, |a, &v| v.is_finite().then(|| a.max(v.abs() as f64)))
        })
        .try_reduce(|| 0f64, |a, b| Some(a.max(b)))
        .ok_or_else(non_finite)?;
    // r_j = m_j − s_j + M s_j in f64 for 32 columns, by row blocks.
    let k = n.min(32);
    let cols: Vec<usize> = (0..k).map(|c| c * n / k).collect();
    let st: Vec<f64> = (0..n)
        .flat_map(|q| cols.iter().map(move |&j| (q, j)))
        .map(|(q, j)| s[(q, j)] as f64)
        .collect(); // st[q * k + c] = S(q, cols[c])
    let mut r = vec![0f64; n * k]; // r[i * k + c]
    r.par_chunks_mut(BLOCK * k)
        .enumerate()
        .for_each(|(b, chunk)| {
            let i0 = b * BLOCK;
            let rows = chunk.len() / k;
            for q in 0..n {
                let mq = &m.col_as_slice(q)[i0..i0 + rows];
                let sq = &st[q * k..(q + 1) * k];
                for (di, &mi) in mq.iter().enumerate() {
                    if mi != 0.0 {
                        let mi = mi as f64;
                        for (acc, &x) in chunk[di * k..(di + 1) * k].iter_mut().zip(sq) {
                            *acc += mi * x;
                        }
                    }
                }
            }
            for di in 0..rows {
                for (c, &j) in cols.iter().enumerate() {
                    chunk[di * k + c] += m[(i0 + di, j)] as f64 - s[(i0 + di, j)] as f64;
                }
            }
        });
    let mut delta = Mat::<f32>::from_fn(n, k, |i, c| r[i * k + c] as f32);
    lu.solve_in_place(delta.as_mut());
    let mut worst = 0f64;
    for c in 0..k {
        for i in 0..n {
            worst = worst.max((delta[(i, c)] as f64).abs());
        }
    }
    // Clamp rounding noise around exact zeros (S is non-negative in exact arithmetic).
    s.par_col_iter_mut().for_each(|col| {
        let c = col.try_as_col_major_mut().unwrap().as_slice_mut();
        c.iter_mut().for_each(|v| *v = v.max(0.0));
    });
    let err = match worst / top.max(f64::MIN_POSITIVE) {
        e if e.is_finite() => e,
        _ => f64::INFINITY,
    };
    Ok((s, err))
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
    let mut x = vec![1f64; n];
    let mut bounds: (f64, f64) = (0.0, f64::INFINITY);
    for _ in 0..64 {
        let y = column_sums(n, n, |j, acc| {
            let xj = x[j];
            if xj != 0.0 {
                for (yi, &v) in acc.iter_mut().zip(m.col_as_slice(j)) {
                    *yi += v as f64 * xj;
                }
            }
        });
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
