//! The upper hulls of the f32 horizon sweep ([`crate::terrain::horizon::sweep_f32`]): N lanes (adjacent
//! lines) per instruction in the vector operations of [`crate::terrain::horizon::lanes`] (eight of AVX2,
//! sixteen of AVX-512), and a portable twin that runs the same f32 operations lane by lane (a
//! proptest holds them bit for bit equal).
//!
//! **One pixel step of a lane** (pixel P at τ_P on the line, f_P = z_P − κτ_P², the line's
//! parabola as in [`crate::terrain::horizon`]; P′ = P + (a, b), the pixel of the step before):
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
//! **Layout of the vector hulls.** Each push takes a slot (the same for every lane; a lane that
//! does not push leaves it unused) that records, per lane, the vertex below the pushed one:
//! the byte offset of its own record (so that a pop reads it with no arithmetic), its height
//! and τ, as one 16-byte record ([`crate::terrain::horizon::lanes::Lanes::store_records`]). A lane's top
//! two vertices live in registers; each pop round reads the third from the second one's record
//! while it tests the top two (AVX2 has sixteen registers: a third vertex in them made the
//! compiler spill the period loop's state, and reading it cost 2 % less than keeping it). The
//! N lanes' records are N 16-byte loads and a transpose: Zen 3 spends 39 µops on each
//! eight-lane gather, and three gathers per pop round (one per field) took 17 % of a build;
//! the records took 5–6 % off its user time (Puget Sound 1024², 64 directions). With sixteen
//! lanes on a Xeon (family 6, model 207), three AVX-512 gathers were 1.5 % faster than the
//! loads (side by side at 1024²), not kept: the microcode fix for Gather Data Sampling makes
//! gathers several times slower on the Skylake to Ice Lake Xeons common in clouds. Pushes are four
//! contiguous vector stores after a transpose: no scatter. Every period sample from the
//! loop's start on is pushed without a branch, in the lanes that keep it (none, often): a
//! branch on whether any lane does, taken about two times in three, mispredicted at a cost
//! higher than the pushes it saved.

#[cfg(target_arch = "x86_64")]
use crate::terrain::horizon::lanes::{pick, Lanes, Top};
use crate::terrain::horizon::lanes::{within, RECORD};

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
pub(super) struct LaneInput<const N: usize> {
    pub count: [i32; N],
    /// The own texel's half transit (less P's height) and P's height.
    pub own: [f32; N],
    pub zp: [f32; N],
    /// −1 where the lane's pixel is on the map, 0 where not.
    pub on: [i32; N],
}

/// The hulls of one bundle's lanes.
pub(super) struct HullsF32<const N: usize> {
    // Vector layout: per slot and lane, the vertex below the one pushed there, as a record
    // [at, y bits, x, x] of four i32 (`RECORD`; `at` is the byte offset of the vertex's own
    // record, `Top`); a slot's N records at the byte offsets `within::<N>()`, in memory in the
    // lane order 0, 4, 1, 5, 2, 6, 3, 7 for eight lanes and 0, 4, 8, 12, 1, 5, 9, 13, ... for
    // sixteen (`Lanes::store_records`).
    below: Vec<i32>,
    slot: usize,
    top: [[i32; N]; 2],
    top_y: [[f32; N]; 2],
    top_x: [[i32; N]; 2],
    // Portable layout: a stack per lane.
    stacks: [LaneStack; N],
    /// f_P′ of the previous step, and where its pixel was on the map.
    f_prev: [f32; N],
    prev_on: [i32; N],
}

impl<const N: usize> HullsF32<N> {
    pub fn new() -> Self {
        HullsF32 {
            below: Vec::new(),
            slot: 1,
            top: [[0; N]; 2],
            top_y: [[0.0; N]; 2],
            top_x: [[0; N]; 2],
            stacks: std::array::from_fn(|_| LaneStack {
                buf: Vec::new(),
                len: 0,
            }),
            f_prev: [0.0; N],
            prev_on: [0; N],
        }
    }

    /// Empty every lane, with room for `pushes` pushes of the vector path.
    pub fn reset(&mut self, pushes: usize) {
        let n = (pushes + 1) * N * RECORD;
        // A record's byte offset is an i32 lane.
        assert!(n * 4 <= i32::MAX as usize, "a bundle of {pushes} pushes");
        if self.below.len() < n {
            self.below.resize(n, 0);
        }
        // Slot 0 is the empty hull's sentinel (slot 0 below slot 0): each of its records
        // points at itself.
        for (i, r) in self.below[..N * RECORD]
            .chunks_exact_mut(RECORD)
            .enumerate()
        {
            r.fill(0);
            r[0] = (i * RECORD * 4) as i32;
        }
        self.slot = 1;
        self.top = [within::<N>(); 2];
        self.top_y = [[0.0; N]; 2];
        self.top_x = [[0; N]; 2];
        for f in &mut self.stacks {
            if f.buf.len() < pushes + 2 {
                f.buf.resize(pushes + 2, (0, 0.0));
            }
            f.len = 0;
        }
        self.prev_on = [0; N];
    }

    /// One pixel step of every lane in the portable kernel; returns each lane's slope (t
    /// units; anything for lanes off the map). The same bits as [`HullsF32::step_simd`]; a
    /// bundle must use one of them throughout.
    #[inline(always)]
    pub fn step(&mut self, s: &Step, l: &LaneInput<N>, heights: &[[f32; N]]) -> [f32; N] {
        let mut out = [0.0; N];
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
    fn step_lane(&mut self, s: &Step, l: &LaneInput<N>, heights: &[[f32; N]], j: usize) -> f32 {
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
fn counts_within<const N: usize>(count: &[i32; N], k: usize) -> bool {
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
impl<const N: usize> HullsF32<N> {
    /// [`HullsF32::step_lane`] for all N lanes at once in the vector operations of `V`
    /// ([`Lanes`]), the same operations in the same order (no FMA): the same bits as
    /// [`HullsF32::step`].
    ///
    /// # Safety
    /// The CPU must have `V`'s features (the caller an entry point compiled for them, into
    /// which this inlines). (A count over k, or negative, would give wrong slopes but read
    /// nothing out of bounds: counts only mask.)
    #[inline(always)]
    pub unsafe fn step_simd<V: Lanes<N>>(
        &mut self,
        s: &Step,
        l: &LaneInput<N>,
        heights: &[[f32; N]],
    ) -> [f32; N] {
        let k = s.offsets.len();
        assert!(self.below.len() >= (self.slot + k + 1) * N * RECORD);
        assert!(heights.len() >= k && s.drop.len() >= k && s.offsets_f.len() >= k);
        assert!(s.near_drop.len() >= k && s.near_inv.len() >= k);
        // The counts only mask lanes (no load depends on them): a check for debug builds.
        debug_assert!(counts_within(&l.count, k));
        // Macros, not closures, for what calls `V`: a closure is compiled without the entry
        // point's features, and the intrinsics in it were not inlined (3x slower).
        macro_rules! ld_i {
            ($a:expr) => {
                V::load_i($a.as_ptr())
            };
        }
        macro_rules! ld_f {
            ($a:expr) => {
                V::load_f($a.as_ptr())
            };
        }
        let (sf, si) = (V::splat_f, V::splat_i);
        let (zp, count) = (ld_f!(l.zp), ld_i!(l.count));
        let on = V::mask_of(ld_i!(l.on));
        // 1. Near; the period's largest slope and its last index.
        let mut near = V::mul(V::sub(ld_f!(l.own), sf(s.own_drop)), sf(s.own_inv));
        let mut best = sf(f32::NEG_INFINITY);
        let mut argmax = si(0);
        // A lane's samples past its count are −∞ (`heights`, [`LaneInput`]): they never reach
        // `best`, nor move `argmax` once a sample has (where none has, `best` stays −∞ and the
        // lane pushes nothing).
        for i in 0..k {
            let v = V::mul(
                V::sub(
                    ld_f!(heights.get_unchecked(i)),
                    sf(*s.near_drop.get_unchecked(i)),
                ),
                sf(*s.near_inv.get_unchecked(i)),
            );
            argmax = V::blend_i(argmax, si(i as i32), V::ge(v, best));
            best = V::max(best, v);
        }
        // P′, the period's far end (index k), where it is on the map.
        let xp = si(s.xp);
        let fp = V::sub(zp, sf(s.drop_p));
        let (f_next, prev_on) = (ld_f!(self.f_prev), V::mask_of(ld_i!(self.prev_on)));
        let dx_next = sf(s.next as f32);
        let slope_next = V::add(
            V::mul(V::div(V::sub(f_next, fp), dx_next), sf(s.scale)),
            sf(s.shift),
        );
        let slope_next = V::blend_f(sf(f32::NEG_INFINITY), slope_next, prev_on);
        argmax = V::blend_i(argmax, si(k as i32), V::ge(slope_next, best));
        best = V::max(best, slope_next);
        near = V::max(near, best);
        // The top two vertices of every lane: record, height, τ.
        macro_rules! top {
            ($k:expr) => {
                Top::<V, N> {
                    at: ld_i!(self.top[$k]),
                    y: ld_f!(self.top_y[$k]),
                    x: ld_i!(self.top_x[$k]),
                }
            };
        }
        let (mut v1, mut v2) = (top!(0), top!(1));
        let below = self.below.as_mut_ptr();
        // Each lane's record within a slot, in bytes (`Lanes::store_records`): the sentinel's.
        let within = V::within();
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
                    let dx1 = V::to_f(V::sub_i(v1.x, xq));
                    let dx2 = V::to_f(V::sub_i(v2.x, xq));
                    let l = V::mul(V::sub(v1.y, yq), dx2);
                    let r = V::mul(V::sub(v2.y, yq), dx1);
                    let deep = V::andnot_m(V::eq_i(v2.at, within), m);
                    let pop = V::and_m(deep, V::le(l, r));
                    if !first && !V::any(pop) {
                        break;
                    }
                    first = false;
                    // The second vertex moves up; the one below it comes from its record
                    // (every lane reads one; those that do not pop keep v2).
                    let v3 = V::load_records(below, v2.at);
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
                V::store_records(below.add(self.slot * N * RECORD), v1);
                let q = Top {
                    at: V::add_i(si((self.slot * N * RECORD * 4) as i32), within),
                    y: yq,
                    x: xq,
                };
                (v1, v2) = (pick(v1, q, m), pick(v2, v1, m));
                self.slot += 1;
            }};
        }
        // 2. Far: the tangent from (τ_P, f_P).
        pop_while!(on, xp, fp, true);
        let dx_far = V::to_f(V::sub_i(v1.x, xp));
        let far = V::add(
            V::mul(V::div(V::sub(v1.y, fp), dx_far), sf(s.scale)),
            sf(s.shift),
        );
        let empty = V::eq_i(v1.at, within);
        let far = V::blend_f(far, sf(f32::NEG_INFINITY), empty);
        // 3. Where the period's largest slope beats the far one, its samples from m on that lie
        // above the chord from P to the far tangent point and their neighbours' segments.
        let active = V::gt(best, far);
        macro_rules! y_at {
            ($i:expr) => {
                V::add(
                    ld_f!(heights.get_unchecked($i)),
                    V::sub(zp, sf(*s.drop.get_unchecked($i))),
                )
            };
        }
        let dx_at = |i: usize| *s.offsets_f.get_unchecked(i);
        // Where every lane has all k samples (away from the map's edge), none needs its count.
        let full = V::all(V::eq_i(count, si(k as i32)));
        // The right end: the last sample kept (P′ first), the far tangent point before any.
        let (mut xr, mut yr) = (dx_far, v1.y);
        let mut has_r = V::not_m(empty);
        // No lane pushes a sample before its period's tangent point (`from` below): the loop
        // stops at the first of those over the active lanes (none where none is active).
        let act_on = V::and_m(active, on);
        let lo = V::min_lane(V::blend_i(si(k as i32 + 1), argmax, act_on)) as usize;
        let mut y = f_next;
        for i in (lo..=k).rev() {
            let (xi, dxv) = if i == k {
                (s.xp + s.next, dx_next)
            } else {
                (s.xp + *s.offsets.get_unchecked(i), sf(dx_at(i)))
            };
            let under = V::le(V::mul(V::sub(y, fp), xr), V::mul(V::sub(yr, fp), dxv));
            // The left neighbour: the next sample nearer P, or P itself.
            let (xl, yl) = if i == 0 {
                (sf(0.0), fp)
            } else {
                (sf(dx_at(i - 1)), y_at!(i - 1))
            };
            let dent = V::le(
                V::mul(V::sub(y, yl), V::sub(xr, xl)),
                V::mul(V::sub(yr, yl), V::sub(dxv, xl)),
            );
            let skip = V::and_m(has_r, V::or_m(under, dent));
            let kept = if i == k {
                V::andnot_m(skip, prev_on)
            } else if full {
                V::not_m(skip)
            } else {
                V::andnot_m(skip, V::gt_i(count, si(i as i32)))
            };
            (xr, yr, has_r) = (
                V::blend_f(xr, dxv, kept),
                V::blend_f(yr, y, kept),
                V::or_m(has_r, kept),
            );
            let from = V::gt_i(si(i as i32 + 1), argmax);
            // Every sample from `lo` on is pushed in the lanes of m, none where m is empty (no
            // pops, and a slot recorded but never read): a branch on m, taken about two times
            // in three, cost more in mispredictions than the push it saved (4 % of a build).
            let m = V::and_m(kept, V::and_m(act_on, from));
            push!(m, si(xi), y);
            y = yl;
        }
        for (k, v) in [v1, v2].into_iter().enumerate() {
            V::store_i(self.top[k].as_mut_ptr(), v.at);
            V::store_i(self.top_x[k].as_mut_ptr(), v.x);
            V::store_f(self.top_y[k].as_mut_ptr(), v.y);
        }
        V::store_f(self.f_prev.as_mut_ptr(), fp);
        V::store_i(self.prev_on.as_mut_ptr(), V::ints_of(on));
        let mut out = [0.0; N];
        V::store_f(out.as_mut_ptr(), V::max(near, far));
        out
    }
}
