//! `form_factors`: F_ij, the fraction of the energy leaving patch i that arrives at patch j
//! (docs/algorithms.md §3):
//!
//! `F_ij = 1/A_i ∫_{A_i} ∫_{A_j} cosθ_i cosθ_j / (π r²) · V(x, y) dA_j dA_i`
//!
//! with visibility V through a BVH of the scene ([`super::visibility`]). Two estimators:
//! [`hemisphere`] shooting (the default: N cosine-distributed rays per patch, `F_ij ≈ hits_j / N`,
//! rows sum to the unoccluded fraction by construction, cost n·N rays) and [`pairwise`]
//! area-to-area (N stratified point pairs per patch pair, one visibility ray each, exactly
//! reciprocal, cost n²·N/2 rays), and [`reciprocal`] averaging of the hemisphere estimate
//! (the two independent estimates of each pair's throughput averaged; no extra rays).
//! [`analytic`] holds closed-form configuration factors for tests.
//!
//! Both are parallel over patches (rayon) with one seeded random stream per patch (or patch
//! pair): the matrix is byte-identical for any thread count.

pub mod analytic;
pub mod hemisphere;
pub mod pairwise;
pub mod reciprocal;

use super::locate::PatchLocator;
use super::visibility::Visibility;
use super::voxelize::piece_sampler;
use super::PatchSet;
use crate::error::{Error, Result};
use crate::progress::Progress;
use crate::scene::Scene;
use serde::{Deserialize, Serialize};

/// Which form-factor estimator to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
pub enum Estimator {
    /// N cosine-distributed rays from each patch (N = samples).
    Hemisphere,
    /// N stratified point pairs per pair of patches, one visibility ray each.
    Pairwise,
    /// Hemisphere shooting, then reciprocity averaging with inverse-variance weights:
    /// `F_ij = A_j (F_ij + F_ji) / (A_i + A_j)`, each row scaled back to the hits' row sum ([`reciprocal`]). The
    /// default: 10–27 % less error in the gathered light than `Hemisphere` with the same rays,
    /// at no extra cost (`relume-bake study radiosity`, docs/radiosity.md).
    #[default]
    HemisphereReciprocal,
}

impl Estimator {
    /// Default samples: rays per patch (hemisphere) or point pairs per patch pair (pairwise).
    pub fn default_samples(self) -> u32 {
        match self {
            Estimator::Hemisphere | Estimator::HemisphereReciprocal => 4096,
            Estimator::Pairwise => 16,
        }
    }
}

/// Knobs of [`form_factors`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FormFactorParams {
    pub estimator: Estimator,
    pub samples: u32,
    pub seed: u64,
}

/// A dense form-factor matrix and what estimating it took.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FormFactors {
    /// Number of patches.
    pub n: usize,
    /// Row-major `[n, n]`: `values[i * n + j] = F_ij`.
    pub values: Vec<f32>,
    /// Visibility rays traced.
    pub rays: u64,
    /// Hemisphere rays whose hit could not be assigned to a patch (should be 0).
    pub unassigned_hits: u64,
}

impl FormFactors {
    pub fn get(&self, i: usize, j: usize) -> f32 {
        self.values[i * self.n + j]
    }

    /// Sum of row i.
    pub fn row_sum(&self, i: usize) -> f64 {
        self.values[i * self.n..(i + 1) * self.n]
            .iter()
            .map(|&v| v as f64)
            .sum()
    }
}

/// What both estimators need: patch samplers, the locator, the BVH.
pub struct Context {
    pub samplers: Vec<crate::radiosity::geometry::AreaSampler>,
    pub locator: PatchLocator,
    pub vis: Visibility,
}

impl Context {
    pub fn new(scene: &Scene, set: &PatchSet) -> Self {
        let samplers = set.patches.iter().map(|p| piece_sampler(set, p)).collect();
        Context {
            samplers,
            locator: PatchLocator::new(set, scene),
            vis: Visibility::for_patches(scene, set),
        }
    }
}

/// Estimate the form factors between the patches of `set` (made by `voxelize` from `scene`).
pub fn form_factors(
    scene: &Scene,
    set: &PatchSet,
    params: &FormFactorParams,
    progress: &dyn Progress,
) -> Result<FormFactors> {
    if params.samples == 0 {
        return Err(Error::knob("form_factors: samples must be at least 1"));
    }
    if set.is_empty() {
        return Err(Error::input("patches", "no patches"));
    }
    let ctx = Context::new(scene, set);
    Ok(match params.estimator {
        Estimator::Hemisphere => hemisphere::estimate(&ctx, params.samples, params.seed, progress),
        Estimator::HemisphereReciprocal => {
            let mut f = hemisphere::estimate(&ctx, params.samples, params.seed, progress);
            let areas: Vec<f64> = ctx.samplers.iter().map(|s| s.area).collect();
            reciprocal::average(&mut f.values, &areas);
            f
        }
        Estimator::Pairwise => pairwise::estimate(&ctx, params.samples, params.seed, progress),
    })
}
