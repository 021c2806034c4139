//! The upper hulls of the f32 horizon sweep ([`super::horizon_f32`]): eight lanes (adjacent
//! lines) per AVX2 instruction, and a portable twin that runs the same f32 operations lane by
//! lane (a proptest holds the two bit for bit equal).
//!
//! **One pixel step of a lane** (pixel P at τ_P on the line, f_P = z_P − κτ_P², the line's
//! parabola as in [`super::horizon`]; P′ = P + (a, b), the pixel of the step before):
//! 1. *Near:* the slope to P's own half transit and to each sample of its period, directly
//!    from the times t_s of the period ((h_s − κt_s² − z_P)/t_s: no large coordinates), and
//!    to P′, the period's far end (a pixel's full transit of its texel is its centre: a chord
//!    through a square's centre is halved there), from the two f values.
//! 2. *Far:* the tangent from (τ_P, f_P) to the hull, which holds the samples beyond P′ that
//!    pixels nearer the line's start may still need, popping the vertices before the tangent
//!    point: they lie under the chord from P to the tangent point, so no pixel further back
//!    can need them (Timonen & Westerholm's amortised O(1) query).
//! 3. *Pushes*, in decreasing τ, of the period's samples and P′ from the last of largest
//!    slope from P (m; ties: the farthest) on, and only where that slope beats the far
//!    tangent. Every sample between P and m lies under the chord from P to m; where the far
//!    tangent wins, every sample of the period and P′ lies under the chord from P to the far
//!    tangent point: such a sample can be the tangent point of no pixel behind P, seen
//!    through P (which the next step weighs as its P′). Of those from m on, a
//!    sample under the chord from P, or from its left neighbour, to the last sample kept to
//!    its right (the far tangent point before any) is skipped too: it lies under a segment
//!    between two samples of the line, one on each side, so seen from any point further left
//!    its slope is at most one of theirs. On Puget Sound (1024², 64 directions) the period
//!    won in 37 % of the lane steps when P′ was pushed as such, and the lane pushes fell from
//!    2.18 to 1.39 per step against the chord and neighbour tests alone; taking the last
//!    sample *kept* as the right end, not the next one, took off another 19 % of lane pushes
//!    (12 % of the vector pushes), with the same bits.
//!
//! P itself is not pushed: the next step decides on it as its P′. Pushed at every step, P was
//! popped again by the next step's far query in most lanes (2.6 pop rounds per step, P's push
//! 0.6 more rounds and a record); as the period's far end it costs a few lane tests, and the
//! planes of Puget Sound at 512² and 1024² came out the same bits.
//!
//! The lane's answer is max(near, far) in t units (a slope per unit of τ).
//!
//! **Coordinates.** τ is held in fixed point (i32, 2^F units per t, F chosen by the caller so
//! that every τ of the line fits in 2^30): differences are exact integers, turned into f32 only
//! as differences, so a sample one period away keeps its place to 2^−F of a texel however far
//! down the line it is. Heights are f32 (the map's own precision).
//!
//! **Layout of the AVX2 hulls.** Each push takes a slot (the same for every lane; a lane that
//! does not push leaves it unused) that records, per lane, the vertex below the pushed one:
//! the byte offset of its own record (so that a pop reads it with no arithmetic), its height
//! and τ, as one 16-byte record ([`super::horizon_records`]). A lane's top two vertices live
//! in registers; each pop round reads the third from the second one's record while it tests
//! the top two (AVX2 has sixteen registers: a third vertex in them made the compiler spill
//! the period loop's state, and reading it cost 2 % less than keeping it). The eight lanes'
//! records are eight 16-byte loads and a transpose: Zen 3 spends 39 µops on each eight-lane
//! gather, and three gathers per pop round (one per field) took 17 % of a build; the records
//! took 5–6 % off its user time (Puget Sound 1024², 64 directions). Pushes are four
//! contiguous vector stores after a transpose: no scatter. Every period sample from the
//! loop's start on is pushed without a branch, in the lanes that keep it (none, often): a
//! branch on whether any lane does, taken about two times in three, mispredicted at a cost
//! higher than the pushes it saved.

use super::horizon_hull::LANES;
#[cfg(target_arch = "x86_64")]
use super::horizon_records::{load_records, min_lane, pick, store_records, Top};
use super::horizon_records::{RECORD, WITHIN};

/// What every lane of one pixel step shares (module notes; `s` indexes the period's samples,
/// nearest first).
pub(super) struct Step<'a> {
    /// τ_P in fixed point, and each period sample's τ less τ_P (exact, and as f32).
    pub xp: i32,
    pub offsets: &'a [i32],
    pub offsets_f: &'a [f32],
    /// κτ² of each sample (the drop on the line's parabola) and of P.
    pub drop: &'a [f32],
    pub drop_p: f32,
    /// κt_s² and 1/t_s of each sample, and of the own half transit.
    pub near_drop: &'a [f32],
    pub near_inv: &'a [f32],
    pub own_drop: f32,
    pub own_inv: f32,
    /// τ_P′ − τ_P in fixed point units, 2^F, and the curvature shift 2κτ_P.
    pub next: i32,
    pub scale: f32,
    pub shift: f32,
}

/// What each lane brings to a step, besides its samples' heights (`heights` in
/// [`HullsF32::step`]: the period samples' heights less P's, [s][lane]; a lane has its first
/// `count[lane]` (near the map's edge, the walk's samples stop there), and −∞ after them where
/// its pixel is on the map).
pub(super) struct LaneInput {
    pub count: [i32; LANES],
    /// The own texel's half transit (less P's height) and P's height.
    pub own: [f32; LANES],
    pub zp: [f32; LANES],
    /// −1 where the lane's pixel is on the map, 0 where not.
    pub on: [i32; LANES],
}

/// The hulls of one bundle's lanes.
pub(super) struct HullsF32 {
    // AVX2 layout: per slot and lane, the vertex below the one pushed there, as a record
    // [at, y bits, x, x] of four i32 (`RECORD`; `at` is the byte offset of the vertex's own
    // record, `Top`); a slot's eight records in lane order
    // 0, 4, 1, 5, 2, 6, 3, 7 (`store_records`).
    below: Vec<i32>,
    slot: usize,
    top: [[i32; LANES]; 2],
    top_y: [[f32; LANES]; 2],
    top_x: [[i32; LANES]; 2],
    // Portable layout: a stack per lane.
    stacks: [LaneStack; LANES],
    /// f_P′ of the previous step, and where its pixel was on the map.
    f_prev: [f32; LANES],
    prev_on: [i32; LANES],
}

impl HullsF32 {
    pub fn new() -> HullsF32 {
        HullsF32 {
            below: Vec::new(),
            slot: 1,
            top: [[0; LANES]; 2],
            top_y: [[0.0; LANES]; 2],
            top_x: [[0; LANES]; 2],
            stacks: std::array::from_fn(|_| LaneStack {
                buf: Vec::new(),
                len: 0,
            }),
            f_prev: [0.0; LANES],
            prev_on: [0; LANES],
        }
    }

    /// Empty every lane, with room for `pushes` pushes of the AVX2 path.
    pub fn reset(&mut self, pushes: usize) {
        let n = (pushes + 1) * LANES * RECORD;
        // A record's byte offset is an i32 lane.
        assert!(n * 4 <= i32::MAX as usize, "a bundle of {pushes} pushes");
        if self.below.len() < n {
            self.below.resize(n, 0);
        }
        // Slot 0 is the empty hull's sentinel (slot 0 below slot 0): each of its records
        // points at itself.
        for (i, r) in self.below[..LANES * RECORD]
            .chunks_exact_mut(RECORD)
            .enumerate()
        {
            r.fill(0);
            r[0] = (i * RECORD * 4) as i32;
        }
        self.slot = 1;
        self.top = [WITHIN; 2];
        self.top_y = [[0.0; LANES]; 2];
        self.top_x = [[0; LANES]; 2];
        for f in &mut self.stacks {
            if f.buf.len() < pushes + 2 {
                f.buf.resize(pushes + 2, (0, 0.0));
            }
            f.len = 0;
        }
        self.prev_on = [0; LANES];
    }

    /// One pixel step of every lane; returns each lane's slope (t units; anything for lanes
    /// off the map). With `avx2` (detected by the caller) the AVX2 kernel, else the portable
    /// one: the same bits. A bundle must use one of them throughout.
    #[inline(always)]
    pub fn step(
        &mut self,
        s: &Step,
        l: &LaneInput,
        heights: &[[f32; LANES]],
        avx2: bool,
    ) -> [f32; LANES] {
        #[cfg(target_arch = "x86_64")]
        if avx2 {
            let k = s.offsets.len();
            assert!(self.below.len() >= (self.slot + k + 1) * LANES * RECORD);
            assert!(heights.len() >= k && s.drop.len() >= k && s.offsets_f.len() >= k);
            assert!(s.near_drop.len() >= k && s.near_inv.len() >= k);
            // The counts only mask lanes (no load depends on them): a check for debug builds.
            debug_assert!(counts_within(&l.count, k));
            // SAFETY: AVX2 was detected; the asserts above give the slots and the lengths.
            return unsafe { self.step_avx2(s, l, heights) };
        }
        let _ = avx2;
        let mut out = [0.0; LANES];
        for (j, o) in out.iter_mut().enumerate() {
            if l.on[j] != 0 {
                *o = self.step_lane(s, l, heights, j);
            }
        }
        self.f_prev = std::array::from_fn(|j| l.zp[j] - s.drop_p);
        self.prev_on = l.on;
        out
    }

    /// Lane j's step (module notes, steps 1–3): the portable kernel.
    #[inline(always)]
    fn step_lane(&mut self, s: &Step, l: &LaneInput, heights: &[[f32; LANES]], j: usize) -> f32 {
        let (zp, count, k) = (l.zp[j], l.count[j] as usize, s.offsets.len());
        let mut near = (l.own[j] - s.own_drop) * s.own_inv;
        let (mut best, mut m) = (f32::NEG_INFINITY, 0usize);
        for (i, row) in heights.iter().enumerate().take(count) {
            let v = (row[j] - s.near_drop[i]) * s.near_inv[i];
            m = if v >= best { i } else { m };
            best = best.max(v);
        }
        let fp = zp - s.drop_p;
        // P′, the period's far end (index k), where it is on the map.
        let (prev_on, f_next) = (self.prev_on[j] != 0, self.f_prev[j]);
        if prev_on {
            let v = (f_next - fp) / s.next as f32 * s.scale + s.shift;
            m = if v >= best { k } else { m };
            best = best.max(v);
        }
        near = near.max(best);
        let st = &mut self.stacks[j];
        st.pop_while(s.xp, fp);
        let (far, mut right) = if st.len > 0 {
            let (x1, y1) = st.top();
            let dx = (x1 - s.xp) as f32;
            ((y1 - fp) / dx * s.scale + s.shift, Some((dx, y1)))
        } else {
            (f32::NEG_INFINITY, None)
        };
        if best > far {
            let y = |i: usize| {
                if i == k {
                    f_next
                } else {
                    heights[i][j] + (zp - s.drop[i])
                }
            };
            let dx = |i: usize| {
                if i == k {
                    s.next as f32
                } else {
                    s.offsets_f[i]
                }
            };
            // The right end: the last sample kept, the far tangent point before any.
            for i in (m..=k).rev() {
                if (i == k && !prev_on) || (i < k && i >= count) {
                    continue;
                }
                let yi = y(i);
                let (xl, yl) = if i == 0 {
                    (0.0, fp)
                } else {
                    (dx(i - 1), y(i - 1))
                };
                if let Some((xr, yr)) = right {
                    if (yi - fp) * xr <= (yr - fp) * dx(i)
                        || (yi - yl) * (xr - xl) <= (yr - yl) * (dx(i) - xl)
                    {
                        continue;
                    }
                }
                right = Some((dx(i), yi));
                let x = s.xp + if i == k { s.next } else { s.offsets[i] };
                st.pop_while(x, yi);
                st.push(x, yi);
            }
        }
        near.max(far)
    }
}

/// Whether every lane's count lies in 0..=k.
#[inline(always)]
fn counts_within(count: &[i32; LANES], k: usize) -> bool {
    let k = k as i32;
    count.iter().fold(true, |ok, &c| ok & (c >= 0) & (c <= k))
}

/// A lane's hull in the portable kernel: a buffer sized by `reset`, with its length.
struct LaneStack {
    buf: Vec<(i32, f32)>,
    len: usize,
}

impl LaneStack {
    #[inline(always)]
    fn top(&self) -> (i32, f32) {
        self.buf[self.len - 1]
    }
    #[inline(always)]
    fn push(&mut self, x: i32, y: f32) {
        self.buf[self.len] = (x, y);
        self.len += 1;
    }
    #[inline(always)]
    fn pop_while(&mut self, xq: i32, yq: f32) {
        let mut n = self.len;
        while n >= 2 {
            let (x1, y1) = self.buf[n - 1];
            let (x2, y2) = self.buf[n - 2];
            if (y1 - yq) * (x2 - xq) as f32 <= (y2 - yq) * (x1 - xq) as f32 {
                n -= 1;
            } else {
                break;
            }
        }
        self.len = n;
    }
}

#[cfg(target_arch = "x86_64")]
impl HullsF32 {
    /// [`HullsF32::step_lane`] for all eight lanes at once, the same operations in the same
    /// order (no FMA).
    ///
    /// # Safety
    /// AVX2 must be available (the caller an AVX2 or wider `#[target_feature]` entry point, into
    /// which this inlines); `below` must have room for k + 1 more slots, and the slices of
    /// `s` and `heights` at least k entries (k = `s.offsets.len()`). (A count over k, or
    /// negative, would give wrong slopes but read nothing out of bounds: counts only mask.)
    #[inline(always)]
    unsafe fn step_avx2(
        &mut self,
        s: &Step,
        l: &LaneInput,
        heights: &[[f32; LANES]],
    ) -> [f32; LANES] {
        use std::arch::x86_64::*;
        let ld_i = |a: &[i32; LANES]| _mm256_loadu_si256(a.as_ptr() as *const __m256i);
        let ld_f = |a: &[f32; LANES]| _mm256_loadu_ps(a.as_ptr());
        let zero = _mm256_setzero_si256();
        let (zp, on, count) = (ld_f(&l.zp), ld_i(&l.on), ld_i(&l.count));
        // 1. Near; the period's largest slope and its last index.
        let mut near = _mm256_mul_ps(
            _mm256_sub_ps(ld_f(&l.own), _mm256_set1_ps(s.own_drop)),
            _mm256_set1_ps(s.own_inv),
        );
        let mut best = _mm256_set1_ps(f32::NEG_INFINITY);
        let mut argmax = zero;
        // A lane's samples past its count are −∞ (`heights`, [`LaneInput`]): they never reach
        // `best`, nor move `argmax` once a sample has (where none has, `best` stays −∞ and the
        // lane pushes nothing).
        for i in 0..s.offsets.len() {
            let v = _mm256_mul_ps(
                _mm256_sub_ps(
                    ld_f(heights.get_unchecked(i)),
                    _mm256_set1_ps(*s.near_drop.get_unchecked(i)),
                ),
                _mm256_set1_ps(*s.near_inv.get_unchecked(i)),
            );
            let ge = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GE_OQ>(v, best));
            argmax = _mm256_blendv_epi8(argmax, _mm256_set1_epi32(i as i32), ge);
            best = _mm256_max_ps(best, v);
        }
        // P′, the period's far end (index k), where it is on the map.
        let xp = _mm256_set1_epi32(s.xp);
        let fp = _mm256_sub_ps(zp, _mm256_set1_ps(s.drop_p));
        let k = s.offsets.len();
        let (f_next, prev_on) = (ld_f(&self.f_prev), ld_i(&self.prev_on));
        let dx_next = _mm256_set1_ps(s.next as f32);
        let slope_next = _mm256_add_ps(
            _mm256_mul_ps(
                _mm256_div_ps(_mm256_sub_ps(f_next, fp), dx_next),
                _mm256_set1_ps(s.scale),
            ),
            _mm256_set1_ps(s.shift),
        );
        let slope_next = _mm256_blendv_ps(
            _mm256_set1_ps(f32::NEG_INFINITY),
            slope_next,
            _mm256_castsi256_ps(prev_on),
        );
        let ge = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GE_OQ>(slope_next, best));
        argmax = _mm256_blendv_epi8(argmax, _mm256_set1_epi32(k as i32), ge);
        best = _mm256_max_ps(best, slope_next);
        near = _mm256_max_ps(near, best);
        // The top two vertices of every lane: record, height, τ.
        let top = |k: usize| Top {
            at: ld_i(&self.top[k]),
            y: ld_f(&self.top_y[k]),
            x: ld_i(&self.top_x[k]),
        };
        let (mut v1, mut v2) = (top(0), top(1));
        let below = self.below.as_mut_ptr();
        // Each lane's record within a slot, in bytes (`store_records`): the sentinel's.
        let within = ld_i(&WITHIN);
        // Pop, in the lanes of mask m, while the top vertex fails the test against (xq, yq).
        // With `eager`, the first round reads the third vertex before its test's branch: the
        // far query's first round pops somewhere in most steps, a push's in few (1.6 rounds
        // with a pop per far query, 0.17 per push: Puget Sound 1024², 64 directions, counted
        // with a probe, since removed). Lazy pushes: 11 % fewer instructions, 0.985x the time.
        macro_rules! pop_while {
            ($m:expr, $xq:expr, $yq:expr, $eager:expr) => {{
                let (m, xq, yq) = ($m, $xq, $yq);
                let mut first = $eager;
                loop {
                    let dx1 = _mm256_cvtepi32_ps(_mm256_sub_epi32(v1.x, xq));
                    let dx2 = _mm256_cvtepi32_ps(_mm256_sub_epi32(v2.x, xq));
                    let l = _mm256_mul_ps(_mm256_sub_ps(v1.y, yq), dx2);
                    let r = _mm256_mul_ps(_mm256_sub_ps(v2.y, yq), dx1);
                    let deep = _mm256_andnot_si256(_mm256_cmpeq_epi32(v2.at, within), m);
                    let pop = _mm256_and_si256(
                        deep,
                        _mm256_castps_si256(_mm256_cmp_ps::<_CMP_LE_OQ>(l, r)),
                    );
                    if !first && _mm256_testz_si256(pop, pop) != 0 {
                        break;
                    }
                    first = false;
                    // The second vertex moves up; the one below it comes from its record
                    // (every lane reads one; those that do not pop keep v2).
                    let v3 = load_records(below, v2.at);
                    (v1, v2) = (pick(v1, v2, pop), pick(v2, v3, pop));
                }
            }};
        }
        // Push (xq, yq) in the lanes of mask m: pop, then record the vertex below in a new slot.
        macro_rules! push {
            ($m:expr, $xq:expr, $yq:expr) => {{
                let (m, xq, yq) = ($m, $xq, $yq);
                pop_while!(m, xq, yq, false);
                record!(m, xq, yq);
            }};
        }
        // Record (xq, yq) on top in the lanes of mask m, in a new slot (no pops).
        macro_rules! record {
            ($m:expr, $xq:expr, $yq:expr) => {{
                let (m, xq, yq) = ($m, $xq, $yq);
                store_records(below.add(self.slot * LANES * RECORD), v1);
                let q = Top {
                    at: _mm256_add_epi32(
                        _mm256_set1_epi32((self.slot * LANES * RECORD * 4) as i32),
                        within,
                    ),
                    y: yq,
                    x: xq,
                };
                (v1, v2) = (pick(v1, q, m), pick(v2, v1, m));
                self.slot += 1;
            }};
        }
        // 2. Far: the tangent from (τ_P, f_P).
        pop_while!(on, xp, fp, true);
        let dx_far = _mm256_cvtepi32_ps(_mm256_sub_epi32(v1.x, xp));
        let far = _mm256_add_ps(
            _mm256_mul_ps(
                _mm256_div_ps(_mm256_sub_ps(v1.y, fp), dx_far),
                _mm256_set1_ps(s.scale),
            ),
            _mm256_set1_ps(s.shift),
        );
        let empty = _mm256_cmpeq_epi32(v1.at, within);
        let far = _mm256_blendv_ps(
            far,
            _mm256_set1_ps(f32::NEG_INFINITY),
            _mm256_castsi256_ps(empty),
        );
        // 3. Where the period's largest slope beats the far one, its samples from m on that lie
        // above the chord from P to the far tangent point and their neighbours' segments.
        let active = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GT_OQ>(best, far));
        let y_at = |i: usize| {
            _mm256_add_ps(
                ld_f(heights.get_unchecked(i)),
                _mm256_sub_ps(zp, _mm256_set1_ps(*s.drop.get_unchecked(i))),
            )
        };
        let dx_at = |i: usize| *s.offsets_f.get_unchecked(i);
        // Where every lane has all k samples (away from the map's edge), none needs its count.
        let full = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(
            count,
            _mm256_set1_epi32(k as i32),
        ))) == 0xff;
        // The right end: the last sample kept (P′ first), the far tangent point before any.
        let (mut xr, mut yr) = (dx_far, v1.y);
        let mut has_r = _mm256_xor_si256(empty, _mm256_set1_epi32(-1));
        // No lane pushes a sample before its period's tangent point (`from` below): the loop
        // stops at the first of those over the active lanes (none where none is active).
        let act_on = _mm256_and_si256(active, on);
        let lo = min_lane(_mm256_blendv_epi8(
            _mm256_set1_epi32(k as i32 + 1),
            argmax,
            act_on,
        )) as usize;
        let mut y = f_next;
        for i in (lo..=k).rev() {
            let (xi, dxv) = if i == k {
                (s.xp + s.next, dx_next)
            } else {
                (s.xp + *s.offsets.get_unchecked(i), _mm256_set1_ps(dx_at(i)))
            };
            let y_p = _mm256_sub_ps(y, fp);
            let under = _mm256_cmp_ps::<_CMP_LE_OQ>(
                _mm256_mul_ps(y_p, xr),
                _mm256_mul_ps(_mm256_sub_ps(yr, fp), dxv),
            );
            // The left neighbour: the next sample nearer P, or P itself.
            let (xl, yl) = if i == 0 {
                (_mm256_setzero_ps(), fp)
            } else {
                (_mm256_set1_ps(dx_at(i - 1)), y_at(i - 1))
            };
            let dent = _mm256_cmp_ps::<_CMP_LE_OQ>(
                _mm256_mul_ps(_mm256_sub_ps(y, yl), _mm256_sub_ps(xr, xl)),
                _mm256_mul_ps(_mm256_sub_ps(yr, yl), _mm256_sub_ps(dxv, xl)),
            );
            let skip = _mm256_and_si256(has_r, _mm256_castps_si256(_mm256_or_ps(under, dent)));
            let kept = if i == k {
                _mm256_andnot_si256(skip, prev_on)
            } else if full {
                _mm256_xor_si256(skip, _mm256_set1_epi32(-1))
            } else {
                _mm256_andnot_si256(skip, _mm256_cmpgt_epi32(count, _mm256_set1_epi32(i as i32)))
            };
            let keptf = _mm256_castsi256_ps(kept);
            (xr, yr, has_r) = (
                _mm256_blendv_ps(xr, dxv, keptf),
                _mm256_blendv_ps(yr, y, keptf),
                _mm256_or_si256(has_r, kept),
            );
            let from = _mm256_cmpgt_epi32(_mm256_set1_epi32(i as i32 + 1), argmax);
            // Every sample from `lo` on is pushed in the lanes of m, none where m is empty (no
            // pops, and a slot recorded but never read): a branch on m, taken about two times
            // in three, cost more in mispredictions than the push it saved (4 % of a build).
            let m = _mm256_and_si256(kept, _mm256_and_si256(act_on, from));
            push!(m, _mm256_set1_epi32(xi), y);
            y = yl;
        }
        let st_i = |a: &mut [i32; LANES], v: __m256i| {
            _mm256_storeu_si256(a.as_mut_ptr() as *mut __m256i, v)
        };
        for (k, v) in [v1, v2].into_iter().enumerate() {
            st_i(&mut self.top[k], v.at);
            st_i(&mut self.top_x[k], v.x);
            _mm256_storeu_ps(self.top_y[k].as_mut_ptr(), v.y);
        }
        _mm256_storeu_ps(self.f_prev.as_mut_ptr(), fp);
        st_i(&mut self.prev_on, on);
        let mut out = [0.0; LANES];
        _mm256_storeu_ps(out.as_mut_ptr(), _mm256_max_ps(near, far));
        out
    }
}
