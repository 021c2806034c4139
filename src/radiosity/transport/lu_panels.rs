//! `S_∞ = (I − M)⁻¹ − I` by columns, in fixed **panels**, so that any subset of panels can be
//! computed by another process and the assembled matrix is byte-identical to the one a single
//! process computes (docs/scale-out.md).
//!
//! One LU with partial pivoting of `A = I − M` in place (faer): `P A = L U`, with
//! `(P x)_i = x_{perm[i]}`. Column j of A⁻¹ is `U⁻¹ L⁻¹ P e_j`, and `P e_j` is the unit vector at
//! position `perm_inv[j]`. Panels are taken in that permuted order: panel p holds the original
//! columns `perm[a..a + w]` with `a = p·w₀`, whose right-hand sides are the identity's columns
//! `a..a + w` — zero above row a, so the forward solve runs on the trailing `L[a.., a..]` only.
//! Summed over panels the forward solves cost n³/3 flops and the backward ones n³: with the LU's
//! 2n³/3, 2n³ in all, the flops of one GEMM, as for the full inverse.
//!
//! A panel's columns depend only on (M, the panel's index): the LU is deterministic (faer splits
//! work the same way for any thread count; `tests/cli/determinism.rs`), the panel width depends only
//! on n, and each panel is solved by its own calls.
//!
//! Off the diagonal `S = A⁻¹`. On it, `A⁻¹ − I` would keep only the absolute precision of the
//! working type near 1, so `S_jj = Σ_q M(j, q) A⁻¹(q, j)` (S = M A⁻¹) is summed in f64 from row j
//! of M and the panel's column. Entries are clamped at 0 (S is non-negative in exact
//! arithmetic) and must be finite.
//!
//! Preconditions: M square and non-negative with spectral radius < 1 (the caller refuses
//! divergent matrices first); `rho` and `f` as in [`RowMajor`].

use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::factor::{lu_in_place, lu_in_place_scratch};
use faer::linalg::triangular_solve::{
    solve_unit_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Mat, Par};
use rayon::prelude::*;

/// M in row-major order as the transport has it: `M(q, i) = rho[q] · f[q·n + i]`.
#[derive(Clone, Copy)]
pub struct RowMajor<'a> {
    pub f: &'a [f32],
    pub rho: &'a [f32],
}

impl RowMajor<'_> {
    /// Row q of F.
    pub fn f_row(&self, q: usize) -> &[f32] {
        let n = self.rho.len();
        &self.f[q * n..(q + 1) * n]
    }
}

/// The working precision of a solve: f32 (the fast one) or f64 (the reference).
pub trait Real: faer::traits::RealField + Copy + Send + Sync {
    fn from64(v: f64) -> Self;
    fn to64(self) -> f64;
}

impl Real for f32 {
    fn from64(v: f64) -> Self {
        v as f32
    }
    fn to64(self) -> f64 {
        self as f64
    }
}

impl Real for f64 {
    fn from64(v: f64) -> Self {
        v
    }
    fn to64(self) -> f64 {
        self
    }
}

/// Columns per panel for n patches: 256 (measured: `cargo bench --bench transport`), fewer for
/// small n so that a few shards still get work (at least 16 panels down to 32 columns).
pub fn panel_width(n: usize) -> usize {
    (n / 16).clamp(32, 512).min(n.max(1))
}

/// Number of panels of an n × n solve.
pub fn panel_count(n: usize) -> usize {
    n.div_ceil(panel_width(n))
}

/// The columns of S of one panel.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Original column indices, in the panel's (permuted) order.
    pub columns: Vec<u32>,
    /// `[columns.len(), n]`: `values[c·n + i] = S(i, columns[c])`.
    pub values: Vec<f32>,
}

/// The LU factors of `I − M` in place, with the row permutation.
pub struct Factored<T: Real> {
    lu: Mat<T>,
    perm: Vec<usize>,
}

/// faer's parallelism for every dense product and solve of the transport: a **fixed** split
/// into 16 parts, run on rayon's pool whatever its size. faer partitions work by the degree it is
/// given, and `Par::rayon(0)` (the pool's size) made S differ between `-j 1` and `-j 2` from
/// about n = 2,000 on (door-ajar.ron); a fixed degree gives the same partition, so the same
/// sums, for any thread count.
pub fn par() -> Par {
    Par::rayon(16)
}

impl<T: Real> Factored<T> {
    /// Factor `I − M`; refuses a zero or non-finite pivot.
    pub fn new(m: RowMajor) -> Result<Self> {
        let n = m.rho.len();
        let mut lu = Mat::<T>::zeros(n, n);
        // Column j of A = I − M reads column j of the row-major F: by blocks of 64 columns, rows
        // in tiles, so reads stay in cache.
        lu.par_col_chunks_mut(64)
            .enumerate()
            .for_each(|(b, mut block)| {
                let j0 = b * 64;
                for i in 0..n {
                    let (r, fi) = (m.rho[i] as f64, m.f_row(i));
                    for dj in 0..block.ncols() {
                        let j = j0 + dj;
                        let v = f64::from(i == j) - r * fi[j] as f64;
                        block[(i, dj)] = T::from64(v);
                    }
                }
            });
        let mut perm = vec![0usize; n];
        let mut perm_inv = vec![0usize; n];
        {
            let mut mem = MemBuffer::new(lu_in_place_scratch::<usize, T>(
                n,
                n,
                par(),
                Default::default(),
            ));
            let stack = MemStack::new(&mut mem);
            lu_in_place(
                lu.as_mut(),
                &mut perm,
                &mut perm_inv,
                par(),
                stack,
                Default::default(),
            );
        }
        check_pivots((0..n).map(|i| lu[(i, i)].to64()))?;
        Ok(Factored { lu, perm })
    }

    pub fn n(&self) -> usize {
        self.perm.len()
    }

    /// The packed factors (column-major, L strictly below the diagonal, U on and above) and the
    /// row permutation, to be stored and read back by [`Factored::from_parts`].
    pub fn to_parts(&self) -> (Vec<T>, Vec<u64>) {
        let n = self.n();
        let mut lu = Vec::with_capacity(n * n);
        for j in 0..n {
            lu.extend_from_slice(self.lu.col_as_slice(j));
        }
        (lu, self.perm.iter().map(|&p| p as u64).collect())
    }

    /// Factors stored by [`Factored::to_parts`]; `None` when the sizes do not agree or the
    /// permutation is not one.
    pub fn from_parts(lu: &[T], perm: &[u64]) -> Option<Self> {
        let n = perm.len();
        if lu.len() != n * n {
            return None;
        }
        let mut seen = vec![false; n];
        for &p in perm {
            let p = p as usize;
            if p >= n || std::mem::replace(&mut seen[p], true) {
                return None;
            }
        }
        Some(Factored {
            lu: Mat::from_fn(n, n, |i, j| lu[j * n + i]),
            perm: perm.iter().map(|&p| p as usize).collect(),
        })
    }

    /// `A⁻¹ B` for k right-hand sides in working precision; `b` and the result are row-major
    /// `[n, k]`.
    pub fn solve_many(&self, b: &[f64], k: usize) -> Vec<f64> {
        let n = self.n();
        let mut x = Mat::<T>::from_fn(n, k, |i, c| T::from64(b[self.perm[i] * k + c]));
        solve_unit_lower_triangular_in_place(self.lu.as_ref(), x.as_mut(), par());
        solve_upper_triangular_in_place(self.lu.as_ref(), x.as_mut(), par());
        (0..n * k).map(|e| x[(e / k, e % k)].to64()).collect()
    }

    /// The columns of S of panel `p` (module notes).
    pub fn panel(&self, p: usize, m: RowMajor) -> Result<Panel> {
        let n = self.n();
        let w0 = panel_width(n);
        let a = p * w0;
        let w = w0.min(n - a);
        let mut x = Mat::<T>::zeros(n, w);
        {
            let mut y = x.as_mut().submatrix_mut(a, 0, n - a, w);
            for c in 0..w {
                y[(c, c)] = T::from64(1.0);
            }
            let l = self.lu.as_ref().submatrix(a, a, n - a, n - a);
            solve_unit_lower_triangular_in_place(l, y, par());
        }
        solve_upper_triangular_in_place(self.lu.as_ref(), x.as_mut(), par());
        let columns: Vec<u32> = self.perm[a..a + w].iter().map(|&j| j as u32).collect();
        let mut values = vec![0f32; w * n];
        values
            .par_chunks_mut(n)
            .enumerate()
            .try_for_each(|(c, out)| {
                let j = columns[c] as usize;
                let col = x.col_as_slice(c);
                let mut diag = 0f64;
                for ((o, &v), &fv) in out.iter_mut().zip(col).zip(m.f_row(j)) {
                    let v = v.to64();
                    if !v.is_finite() {
                        return Err(non_finite());
                    }
                    diag += fv as f64 * v;
                    *o = v.max(0.0) as f32;
                }
                out[j] = (m.rho[j] as f64 * diag).max(0.0) as f32;
                Ok(())
            })?;
        Ok(Panel { columns, values })
    }
}

/// Write panels into the row-major `[n, n]` S (`out[i·n + j] = S(i, j)`), by row blocks.
pub fn scatter(panels: &[Panel], n: usize, out: &mut [f32]) {
    out.par_chunks_mut(64 * n.max(1))
        .enumerate()
        .for_each(|(b, chunk)| {
            let i0 = b * 64;
            let rows = chunk.len() / n.max(1);
            for p in panels {
                for (c, &j) in p.columns.iter().enumerate() {
                    let col = &p.values[c * n + i0..c * n + i0 + rows];
                    for (di, &v) in col.iter().enumerate() {
                        chunk[di * n + j as usize] = v;
                    }
                }
            }
        });
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

pub(super) fn non_finite() -> Error {
    Error::knob(
        "transport: the infinite-bounce solve produced a non-finite value; use `bounces: Finite(k)`",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// S from the panels against the Neumann series Σ M^h summed to convergence in f64.
    #[test]
    fn panels_assemble_the_neumann_series() {
        for n in [1usize, 5, 37, 70] {
            let rho: Vec<f32> = (0..n)
                .map(|i| 0.3 + 0.5 * ((i * 7) % 5) as f32 / 5.0)
                .collect();
            let f: Vec<f32> = (0..n * n)
                .map(|k| ((k * 31 + 7) % 13) as f32 / (13.0 * n as f32))
                .collect();
            let m = RowMajor { f: &f, rho: &rho };
            let mm = |i: usize, j: usize| rho[i] as f64 * f[i * n + j] as f64;
            let mut s = vec![0f64; n * n];
            let mut term: Vec<f64> = (0..n * n).map(|k| mm(k / n, k % n)).collect();
            for _ in 0..200 {
                for k in 0..n * n {
                    s[k] += term[k];
                }
                let mut next = vec![0f64; n * n];
                for i in 0..n {
                    for q in 0..n {
                        for j in 0..n {
                            next[i * n + j] += mm(i, q) * term[q * n + j];
                        }
                    }
                }
                term = next;
            }
            for prec in 0..2 {
                let panels: Vec<Panel> = if prec == 0 {
                    let fac = Factored::<f32>::new(m).unwrap();
                    (0..panel_count(n))
                        .map(|p| fac.panel(p, m).unwrap())
                        .collect()
                } else {
                    let fac = Factored::<f64>::new(m).unwrap();
                    (0..panel_count(n))
                        .map(|p| fac.panel(p, m).unwrap())
                        .collect()
                };
                let mut seen = vec![false; n];
                for p in &panels {
                    for &j in &p.columns {
                        assert!(!seen[j as usize], "column {j} twice");
                        seen[j as usize] = true;
                    }
                }
                assert!(seen.iter().all(|&s| s), "every column once");
                let mut out = vec![0f32; n * n];
                scatter(&panels, n, &mut out);
                let tol = if prec == 0 { 2e-6 } else { 1e-7 };
                for k in 0..n * n {
                    assert!(
                        (out[k] as f64 - s[k]).abs() <= tol * (1.0 + s[k]),
                        "n {n} prec {prec} entry {k}: {} vs {}",
                        out[k],
                        s[k]
                    );
                }
            }
        }
    }
}
