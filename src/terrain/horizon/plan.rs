//! What every bundle of one direction of the f32 horizon sweep ([`crate::terrain::horizon::sweep_f32`])
//! shares — the periods' stencils in f32 with their texel offsets, the samples' times in fixed
//! point, the steps at which a bundle's stencils all lie on the map — and the stencils'
//! bilinear samples: one lane at a time ([`eval_lane`]) and N lanes in the vector operations of
//! [`crate::terrain::horizon::lanes`] ([`eval_simd`]), the same bits.

use crate::heightmap::HeightMap;
#[cfg(target_arch = "x86_64")]
use crate::terrain::horizon::lanes::Lanes;
use crate::terrain::horizon::{period, Direction, Stencils};

/// What every bundle of one direction shares.
pub(super) struct Plan<'a> {
    pub map: &'a HeightMap,
    pub dir: Direction,
    pub track: crate::terrain::sun::Track,
    pub per: Vec<crate::terrain::horizon::PeriodTexel>,
    pub stencils: Stencils,
    /// The period samples' t from the pixel, nearest first.
    pub ts: Vec<f64>,
    pub near_drop: Vec<f32>,
    pub near_inv: Vec<f32>,
    pub period_t: f64,
    pub kappa: f64,
    /// Fixed-point units per t (2^F), and each period sample's t in them (exact i32, and as
    /// f32: a sample's τ less P's).
    pub units: f64,
    pub offsets: Vec<i32>,
    pub offsets_f: Vec<f32>,
    /// The stencils in f32 with their texel offsets from the pixel: the period's, and the own
    /// half transit's.
    pub taps: Vec<Tap>,
    pub own_tap: Tap,
    /// The texel offsets from a step's lane-0 pixel of the two ends of each row its stencils
    /// read, [`AHEAD`] steps further on ([`prefetch`]).
    pub ahead: Vec<isize>,
    /// Lines per bundle.
    pub lanes: usize,
}

/// A stencil in f32 ([`eval_f32`]): its top-left tap's offset from the pixel in the map's
/// row-major order, and its weights.
#[derive(Clone, Copy)]
pub(super) struct Tap {
    at: isize,
    tx: f32,
    ty: f32,
}

impl<'a> Plan<'a> {
    pub fn new(
        map: &'a HeightMap,
        dir: &Direction,
        planet_radius: Option<f64>,
        lanes: usize,
    ) -> Self {
        let track = dir.track(map.cell_size);
        let per = period(&track, dir);
        let stencils = Stencils::new(&track, dir, &per);
        let kappa = planet_radius.map_or(0.0, |r| track.metres_per_t.powi(2) / (2.0 * r));
        let period_t = (dir.a as f64).hypot(dir.b as f64);
        let ts: Vec<f64> = stencils.period.iter().map(|s| s.t).collect();
        // Every τ of a line: at most (rows/|b| + 2) periods; F bits of fraction keep it < 2^30.
        let tau_max = (map.height as f64 / dir.b.abs() as f64 + 2.0) * period_t;
        let bits = ((1u64 << 30) as f64 / tau_max)
            .log2()
            .floor()
            .clamp(0.0, 24.0);
        let w = map.width as isize;
        let tap = |s: &crate::terrain::horizon::Stencil| Tap {
            at: s.dy as isize * w + s.dx as isize,
            tx: s.tx as f32,
            ty: s.ty as f32,
        };
        let (taps, own_tap) = (
            stencils.period.iter().map(tap).collect(),
            tap(&stencils.own),
        );
        let units = 2f64.powi(bits as i32);
        let offsets: Vec<i32> = ts.iter().map(|&t| fixed(t, units)).collect();
        let st = &stencils;
        let back = AHEAD as isize * (dir.b as isize * w + dir.a as isize);
        let ahead = (st.lo[1]..=st.hi[1])
            .flat_map(|y| {
                [st.lo[0], lanes as i64 - 1 + st.hi[0]].map(|x| y as isize * w + x as isize - back)
            })
            .collect();
        Plan {
            map,
            dir: *dir,
            track,
            per,
            near_drop: ts.iter().map(|&t| (kappa * t * t) as f32).collect(),
            near_inv: ts.iter().map(|&t| (1.0 / t) as f32).collect(),
            ts,
            stencils,
            period_t,
            kappa,
            units,
            lanes,
            offsets_f: offsets.iter().map(|&o| o as f32).collect(),
            offsets,
            taps,
            own_tap,
            ahead,
        }
    }

    /// The steps n of the bundle starting at (r₀, x₀) whose lanes' stencils all lie on the
    /// map (empty when lo > hi): r = r₀ + n·b and c₀ = x₀ + n·a are linear in n, so the
    /// conditions on the stencils' box hold on an interval.
    pub fn fitting(&self, (r0, x0): (i64, i64)) -> (i64, i64) {
        let (w, h) = (self.map.width as i64, self.map.height as i64);
        let st = &self.stencils;
        let (a, b) = (self.dir.a, self.dir.b);
        let rows = steps_within(-st.lo[1] - r0, h - 1 - st.hi[1] - r0, b);
        let cols = steps_within(-st.lo[0] - x0, w - self.lanes as i64 - st.hi[0] - x0, a);
        (rows.0.max(cols.0), rows.1.min(cols.1))
    }

    /// τ ≥ 0 to the nearest fixed-point unit ([`fixed`]).
    pub fn fixed(&self, tau: f64) -> i32 {
        fixed(tau, self.units)
    }
}

/// τ ≥ 0 to the nearest of `units` per t (halves up; no libm call).
fn fixed(tau: f64, units: f64) -> i32 {
    (tau * units + 0.5) as i32
}

/// The n with lo ≤ n·q ≤ hi, as an interval (empty when its start exceeds its end).
fn steps_within(lo: i64, hi: i64, q: i64) -> (i64, i64) {
    let ceil = |p: i64, q: i64| -(-p).div_euclid(q);
    match q.signum() {
        0 if lo <= 0 && 0 <= hi => (i64::MIN, i64::MAX),
        0 => (1, 0),
        1 => (ceil(lo, q), hi.div_euclid(q)),
        _ => (ceil(-hi, -q), (-lo).div_euclid(-q)),
    }
}

/// How many steps ahead of the walk [`prefetch`] asks for the map's rows. On Puget Sound
/// 4096² (64 directions) 1 to 8 steps all gain; 2 gained most, 7 % of the user time against
/// prefetching the step being taken.
pub(super) const AHEAD: i64 = 2;

/// Ask for the map's texels under the stencils of the step [`AHEAD`] steps on from the one
/// whose lane 0 is pixel `base` (row-major), when all of them are on the map (the caller's
/// test): the walk crosses the map along its direction, b rows a step, so the hardware's
/// prefetchers do not see its rows coming (at 4096², 64 directions, the stencils' loads took a
/// third of the build's time without this).
#[inline(always)]
pub(super) fn prefetch(plan: &Plan, base: i64) {
    #[cfg(target_arch = "x86_64")]
    for &o in &plan.ahead {
        // SAFETY: SSE is part of x86-64; a prefetch is only a hint, and `wrapping_offset`
        // forms its address without dereferencing it (the caller's test keeps it on the map).
        unsafe {
            use std::arch::x86_64::*;
            let p = plan.map.heights.as_ptr().wrapping_offset(base as isize + o);
            _mm_prefetch::<_MM_HINT_T0>(p as *const i8);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (plan, base);
}

/// A stencil's bilinear sample in f32 ([`Stencil::eval`]'s operations) relative to the
/// pixel's height z: each row's first tap less z, plus the row's own difference times the
/// weight, so that a sample near the pixel keeps the precision of its height difference, not
/// of the heights. (The row's difference b − a is one rounding of the exact one, exact where
/// the taps are within a factor two: no less precise than (b − z) − (a − z), and two
/// subtractions fewer; the planes of Puget Sound at 512² and 1024² did not change.) Unlike the
/// f64 `eval`, no clamp
/// to the taps' range: the blend is a convex combination, which f32 rounding can carry past
/// the range by an ulp of the height difference at most, far below the error budget; the
/// clamp's eight operations were 2–3 % of a horizon build, and on Puget Sound at 1024² and
/// 4096² (64 directions) no quantised angle changed without them.
#[inline]
fn eval_f32(tap: &Tap, hs: &[f32], pixel: usize, w: usize, z: f32) -> f32 {
    let i = (pixel as isize + tap.at) as usize;
    let (a, b, c, d) = (hs[i], hs[i + 1], hs[i + w], hs[i + w + 1]);
    let (tx, ty) = (tap.tx, tap.ty);
    let top = (a - z) + (b - a) * tx;
    let bottom = (c - z) + (d - c) * tx;
    top + (bottom - top) * ty
}

/// Every stencil of lane j's pixel (all its taps on the map), relative to its height `z`.
#[inline(always)]
pub(super) fn eval_lane<const N: usize>(
    plan: &Plan,
    pixel: usize,
    z: f32,
    j: usize,
    heights: &mut [[f32; N]],
    own: &mut [f32; N],
) {
    let (hs, w) = (&plan.map.heights[..], plan.map.width);
    for (tap, row) in plan.taps.iter().zip(heights.iter_mut()) {
        row[j] = eval_f32(tap, hs, pixel, w, z);
    }
    own[j] = eval_f32(&plan.own_tap, hs, pixel, w, z);
}

/// Every stencil of the N lanes' pixels `base + j` (all taps on the map, checked here once
/// for the stencils' box), relative to their heights `z`, in the vector operations of `V`:
/// [`eval_f32`]'s operations, the same bits; the period's into `heights`, the own half transit
/// into `own`.
///
/// # Safety
/// The CPU must have `V`'s features (the caller an entry point compiled for them, into which
/// this inlines).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) unsafe fn eval_simd<V: Lanes<N>, const N: usize>(
    plan: &Plan,
    base: usize,
    z: &[f32; N],
    heights: &mut [[f32; N]],
    own: &mut [f32; N],
) {
    let (hs, w) = (&plan.map.heights[..], plan.map.width);
    let st = &plan.stencils;
    let lo = base as isize + st.lo[1] as isize * w as isize + st.lo[0] as isize;
    let hi = base as isize + st.hi[1] as isize * w as isize + st.hi[0] as isize;
    assert!(lo >= 0 && hi + N as isize <= hs.len() as isize);
    let p = hs.as_ptr().add(base);
    let z = V::load_f(z.as_ptr());
    for (tap, out) in plan.taps.iter().zip(heights.iter_mut()) {
        eval_tap::<V, N>(tap, p, w, z, out);
    }
    eval_tap::<V, N>(&plan.own_tap, p, w, z, own);
}

/// [`eval_f32`] of one stencil for the N lanes whose pixel 0 is at `p`, their heights `z`.
///
/// # Safety
/// As [`eval_simd`]; the taps of lanes 0..N must lie in the map `p` points into.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn eval_tap<V: Lanes<N>, const N: usize>(
    tap: &Tap,
    p: *const f32,
    w: usize,
    z: V::F,
    out: &mut [f32; N],
) {
    let (tx, ty) = (V::splat_f(tap.tx), V::splat_f(tap.ty));
    let p = p.offset(tap.at);
    let (a, b) = (V::load_f(p), V::load_f(p.add(1)));
    let (c, d) = (V::load_f(p.add(w)), V::load_f(p.add(w + 1)));
    let top = V::add(V::sub(a, z), V::mul(V::sub(b, a), tx));
    let bottom = V::add(V::sub(c, z), V::mul(V::sub(d, c), tx));
    let v = V::add(top, V::mul(V::sub(bottom, top), ty));
    V::store_f(out.as_mut_ptr(), v);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::terrain::horizon::test_maps::{map, steep};
    use crate::terrain::horizon::{bundle_list, directions};
    use proptest::prelude::*;

    proptest! {
        /// `steps_within` is exactly the n with lo ≤ n·q ≤ hi (brute force over a window
        /// wider than every answer drawn here).
        #[test]
        fn steps_within_is_the_brute_force_interval(
            lo in -60i64..60, span in -5i64..60, q in -7i64..8,
        ) {
            let hi = lo + span;
            let (a, b) = steps_within(lo, hi, q);
            for n in -200i64..=200 {
                let inside = lo <= n * q && n * q <= hi;
                prop_assert_eq!(inside, a <= n && n <= b, "n {} q {} [{}, {}]", n, q, lo, hi);
            }
        }

        /// A bundle's all-fit interval holds exactly the steps at which every lane's stencils
        /// lie on the map (the box test per step that it replaces).
        #[test]
        fn fitting_steps_are_those_whose_stencils_lie_on_the_map(
            w in 8usize..70, h in 8usize..70, k in 0usize..64,
        ) {
            let m = map(w, h, 7);
            let d = steep(directions(64, m.cell_size)[k]);
            for lanes in [8, 16] {
                let plan = Plan::new(&m, &d, None, lanes);
                let (st, (wi, hi)) = (&plan.stencils, (w as i64, h as i64));
                for &(r0, x0, n0, n1) in &bundle_list(&m, &d, lanes) {
                    let (f0, f1) = plan.fitting((r0, x0));
                    for n in n0..=n1 {
                        let (r, c0) = (r0 + n * d.b, x0 + n * d.a);
                        let fits = r + st.lo[1] >= 0
                            && r + st.hi[1] < hi
                            && c0 + st.lo[0] >= 0
                            && c0 + lanes as i64 - 1 + st.hi[0] < wi;
                        prop_assert_eq!(fits, f0 <= n && n <= f1, "{:?} {:?} n {}", d, (r0, x0), n);
                    }
                }
            }
        }
    }
}
