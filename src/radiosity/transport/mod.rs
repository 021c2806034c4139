//! `transport`: the k-bounce transport matrix (docs/algorithms.md §3), per colour channel
//!
//! `S_k = Σ_{h=1..k} M^h`,  `M = diag(ρ) F`,  so that the indirect light of direct exitance E is
//! `B_indirect = S_k · E` (the radiosity thesis's `F^{k-reflections}`, §4.1, with its "colour matrix" `F^C = M`),
//!
//! and the limit `S_∞ = M (I − M)^{-1} = (I − M)^{-1} M`, by one LU factorisation (partial
//! pivoting, faer) in f32 checked a posteriori, or in f64 when the check fails
//! ([`crate::radiosity::transport::infinite`]). Finite k uses f32 GEMMs (faer) by Horner's rule
//! (`S ← M + M·S`, k − 1 products) or binary doubling (`S_2m = S_m + M^m S_m`,
//! `S_{m+1} = M + M S_m`, about 2 log2 k products); `Power::Auto` takes the one with fewer
//! products (Horner on ties; the benchmark in benches/transport.rs measures both).
//! `Bounces::Auto(tol)` adds bounces by Horner until the newest bounce's largest row sum
//! `‖M^h‖_∞` (the most light it can add per unit of emission) is below `tol`.
//!
//! Grey scenes (R = G = B albedo everywhere) compute one channel. Infinite and Auto refuse, with a
//! clear message, a matrix whose spectral radius is (numerically) 1 or more — a closed scene with
//! albedo 1 never loses energy — instead of returning huge or NaN entries.

pub mod infinite;
pub mod lu_panels;
pub mod matrix;
pub mod reference;
pub mod shard;

use crate::error::{Error, Result};
use crate::limits;
use crate::progress::Progress;
use crate::radiosity::transport::infinite::{
    from_fn_tiled, infinite, to_row_major, RowMajor, F32_BYTES_PER_ENTRY,
};
pub use crate::radiosity::transport::infinite::{
    spectral_bounds, spectral_bounds_rows, InfiniteSolver, F32_ACCEPT,
};
use crate::radiosity::transport::lu_panels::par;
use crate::radiosity::TransportMatrix;
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat};
use serde::{Deserialize, Serialize};

/// How many bounces the transport matrix accumulates.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Bounces {
    /// Exactly k ≥ 1 bounces.
    Finite(u32),
    /// All bounces: `M (I − M)^{-1}`.
    Infinite,
    /// Add bounces until one more adds less than this tolerance (`‖M^h‖_∞`).
    Auto(f64),
}

/// How `S_k` is evaluated for finite k.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Power {
    /// Whichever of Horner and doubling needs fewer matrix products.
    #[default]
    Auto,
    /// `S ← M + M·S`, k − 1 products.
    Horner,
    /// Binary doubling, about 2·log2(k) products.
    Doubling,
}

/// Most bounces `Bounces::Auto` will add before giving up.
pub const MAX_AUTO_BOUNCES: u32 = 10_000;
/// Spectral radii at or above `1 − this` are refused for Infinite and Auto.
const SPECTRAL_MARGIN: f64 = 1e-6;

/// Knobs of [`transport`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TransportParams {
    pub bounces: Bounces,
    pub power: Power,
    /// Memory budget in bytes (`--max-memory`).
    pub max_memory: u64,
    /// How infinite bounces are solved.
    pub solver: InfiniteSolver,
}

/// The transport matrices of every modelled channel, with what computing them took.
#[derive(Clone, Debug, PartialEq)]
pub struct Transport {
    /// `S` per channel (1 for grey scenes, else 3).
    pub matrix: TransportMatrix,
    /// Bounces accumulated per channel (0 = infinite).
    pub bounces: Vec<u32>,
    /// Matrix products (GEMMs) performed, all channels.
    pub products: u32,
    /// Collatz–Wielandt bounds on the spectral radius of M per channel (lower, upper); computed
    /// for Infinite and Auto only.
    pub spectral_bounds: Vec<(f64, f64)>,
    /// Infinite only, per channel: which LU solved it and the f32 solve's estimated relative
    /// error ([`crate::radiosity::transport::infinite`]).
    pub solvers: Vec<(InfiniteSolver, f64)>,
}

/// A transport is its matrix plus how it was computed: `t.channels`, `t.apply(..)` read the
/// matrix.
impl std::ops::Deref for Transport {
    type Target = TransportMatrix;
    fn deref(&self) -> &TransportMatrix {
        &self.matrix
    }
}

/// Estimated peak bytes of [`transport`]: the form factors, the output, and the working
/// matrices of one channel (finite and Auto: up to four f32 matrices — M, S, M^j or the newest
/// bounce, scratch; infinite: the f32 solve's [`F32_BYTES_PER_ENTRY`]; when the f32 solve is
/// not accurate enough, the f64 one's larger need is checked against the budget again first).
pub fn memory_estimate(n: usize, channels: usize, bounces: Bounces) -> u64 {
    let n2 = (n * n) as u64;
    let working = match bounces {
        Bounces::Infinite => n2 * F32_BYTES_PER_ENTRY,
        _ => n2 * 4 * 4,
    };
    n2 * 4 + channels as u64 * n2 * 4 + working
}

/// Compute the transport matrix from `f` (`[n, n]` row-major F) and per-patch albedo.
pub fn transport(
    f: &[f32],
    n: usize,
    albedo: &[[f32; 3]],
    params: &TransportParams,
    progress: &dyn Progress,
) -> Result<Transport> {
    if f.len() != n * n || albedo.len() != n {
        return Err(Error::Internal(format!(
            "transport: {} form factors and {} albedos for {n} patches",
            f.len(),
            albedo.len()
        )));
    }
    match params.bounces {
        Bounces::Finite(0) => return Err(Error::knob("transport: bounces Finite(k) needs k ≥ 1")),
        Bounces::Auto(t) if !(t.is_finite() && t > 0.0) => {
            return Err(Error::knob(format!(
                "transport: Auto tolerance must be a positive number, got {t}"
            )))
        }
        _ => {}
    }
    let grey = albedo.iter().all(|a| a[0] == a[1] && a[1] == a[2]);
    let channels = if grey { 1 } else { 3 };
    limits::check_memory(
        &format!("the transport of {n} patches x {channels} channel(s)"),
        memory_estimate(n, channels, params.bounces),
        params.max_memory,
    )?;
    let mut values = Vec::with_capacity(channels * n * n);
    let mut out = Transport {
        matrix: TransportMatrix::zeros(channels, 0),
        bounces: Vec::new(),
        products: 0,
        spectral_bounds: Vec::new(),
        solvers: Vec::new(),
    };
    progress.begin("transport", channels as u64);
    for c in 0..channels {
        let rho: Vec<f32> = albedo.iter().map(|a| a[c]).collect();
        let rows = RowMajor { f, rho: &rho };
        if params.bounces == Bounces::Infinite {
            let bounds = infinite_bounds(rows)?;
            out.spectral_bounds.push(bounds);
            let n2 = (n * n) as u64;
            let check = |bytes: u64, why: String| {
                limits::check_memory(
                    &why,
                    n2 * 4 + channels as u64 * n2 * 4 + bytes,
                    params.max_memory,
                )
            };
            let (s, solver, err) = infinite(rows, params.solver, &check)?;
            out.solvers.push((solver, err));
            out.bounces.push(0);
            values.extend(s);
            progress.advance(1);
            continue;
        }
        let m = from_fn_tiled(n, |i, j| rho[i] * f[i * n + j]);
        let (s, k, products) = match params.bounces {
            Bounces::Finite(k) => {
                let (s, p) = power_sum(&m, k, params.power);
                (s, k, p)
            }
            Bounces::Auto(tol) => {
                let bounds = spectral_bounds(&m, None);
                out.spectral_bounds.push(bounds);
                refuse_divergent(bounds, "Auto")?;
                auto_sum(&m, tol)?
            }
            Bounces::Infinite => unreachable!("solved above"),
        };
        out.bounces.push(k);
        out.products += products;
        values.extend(to_row_major(&s));
        progress.advance(1);
    }
    progress.finish();
    out.matrix = TransportMatrix::new(channels, n, values)?;
    Ok(out)
}

/// The spectral bounds of M for infinite bounces, refusing a divergent M. Only the refusal needs
/// them: once the largest row sum of M is below 1 − margin (every albedo below 1 and rows summing
/// to at most 1), the spectral radius is too, and the power iteration stops after its first step.
pub fn infinite_bounds(rows: RowMajor) -> Result<(f64, f64)> {
    let bounds = spectral_bounds_rows(rows, Some(1.0 - SPECTRAL_MARGIN));
    refuse_divergent(bounds, "Infinite")?;
    Ok(bounds)
}

fn refuse_divergent(bounds: (f64, f64), what: &str) -> Result<()> {
    if bounds.0 >= 1.0 - SPECTRAL_MARGIN {
        return Err(Error::knob(format!(
            "transport: bounces {what} diverges here: the spectral radius of diag(albedo)·F is at least {:.7} \
             (light never dies out — a closed scene with albedo 1 reflects everything forever). \
             Use `bounces: Finite(k)`, or lower the albedo below 1",
            bounds.0
        )));
    }
    Ok(())
}

/// `dst = a · b` (Accum::Replace) or `dst += a · b` (Accum::Add).
fn gemm(dst: &mut Mat<f32>, accum: Accum, a: &Mat<f32>, b: &Mat<f32>) {
    matmul(dst.as_mut(), accum, a.as_ref(), b.as_ref(), 1.0f32, par());
}

/// Number of products Horner and doubling need for `k` bounces.
pub fn products(k: u32) -> (u32, u32) {
    let horner = k.saturating_sub(1);
    let bits = 32 - k.leading_zeros();
    let mut doubling = 0;
    for b in (0..bits.saturating_sub(1)).rev() {
        let more = b > 0;
        let set = (k >> b) & 1 == 1;
        doubling += 1 + u32::from(more || set); // S ← S + P S; P ← P P when still needed
        if set {
            doubling += 1 + u32::from(more); // S ← M + M S; P ← M P when still needed
        }
    }
    (horner, doubling)
}

/// `Σ_{h=1..k} M^h` and the number of products used.
pub fn power_sum(m: &Mat<f32>, k: u32, power: Power) -> (Mat<f32>, u32) {
    let (h, d) = products(k);
    let use_doubling = match power {
        Power::Auto => d < h,
        Power::Horner => false,
        Power::Doubling => true,
    };
    if use_doubling {
        (doubling(m, k), d)
    } else {
        (horner(m, k), h)
    }
}

fn horner(m: &Mat<f32>, k: u32) -> Mat<f32> {
    let mut s = m.clone();
    let mut next = m.clone();
    for _ in 1..k {
        next.copy_from(m);
        gemm(&mut next, Accum::Add, m, &s);
        std::mem::swap(&mut s, &mut next);
    }
    s
}

fn doubling(m: &Mat<f32>, k: u32) -> Mat<f32> {
    let bits = 32 - k.leading_zeros();
    let mut s = m.clone();
    let mut p = m.clone(); // P = M^j for the current j
    let mut tmp = Mat::<f32>::zeros(m.nrows(), m.ncols());
    for b in (0..bits.saturating_sub(1)).rev() {
        let more = b > 0;
        let set = (k >> b) & 1 == 1;
        tmp.copy_from(&s);
        gemm(&mut tmp, Accum::Add, &p, &s); // S_2j = S_j + M^j S_j
        std::mem::swap(&mut s, &mut tmp);
        if more || set {
            gemm(&mut tmp, Accum::Replace, &p, &p); // M^2j
            std::mem::swap(&mut p, &mut tmp);
        }
        if set {
            tmp.copy_from(m);
            gemm(&mut tmp, Accum::Add, m, &s); // S_{2j+1} = M + M S_2j
            std::mem::swap(&mut s, &mut tmp);
            if more {
                gemm(&mut tmp, Accum::Replace, m, &p); // M^{2j+1}
                std::mem::swap(&mut p, &mut tmp);
            }
        }
    }
    s
}

/// Largest row sum (∞-norm) of a non-negative matrix.
fn max_row_sum(a: &Mat<f32>) -> f64 {
    let mut sums = vec![0f64; a.nrows()];
    for j in 0..a.ncols() {
        for (i, s) in sums.iter_mut().enumerate() {
            *s += a[(i, j)].abs() as f64;
        }
    }
    sums.into_iter().fold(0.0, f64::max)
}

fn auto_sum(m: &Mat<f32>, tol: f64) -> Result<(Mat<f32>, u32, u32)> {
    let mut s = m.clone();
    let mut term = m.clone();
    let mut next = Mat::<f32>::zeros(m.nrows(), m.ncols());
    let mut k = 1;
    let mut products = 0;
    while max_row_sum(&term) >= tol {
        if k >= MAX_AUTO_BOUNCES {
            return Err(Error::knob(format!(
                "transport: Auto({tol}) still adds more than the tolerance after {MAX_AUTO_BOUNCES} bounces; use a larger tolerance or Infinite"
            )));
        }
        gemm(&mut next, Accum::Replace, m, &term);
        std::mem::swap(&mut term, &mut next);
        s += &term;
        k += 1;
        products += 1;
    }
    Ok((s, k, products))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn product_counts() {
        assert_eq!(products(1), (0, 0));
        assert_eq!(products(2), (1, 1));
        assert_eq!(products(8), (7, 5));
        assert_eq!(products(3), (2, 3));
    }

    #[test]
    fn horner_and_doubling_agree() {
        let m = Mat::<f32>::from_fn(5, 5, |i, j| 0.04 * ((i * 7 + j * 3) % 5) as f32);
        for k in 1..12 {
            let (a, b) = (horner(&m, k), doubling(&m, k));
            for i in 0..5 {
                for j in 0..5 {
                    assert!((a[(i, j)] - b[(i, j)]).abs() < 1e-6, "k={k}");
                }
            }
        }
    }
}
