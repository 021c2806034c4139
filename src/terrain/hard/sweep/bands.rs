//! The band state of the certified sweep ([`crate::terrain::hard::sweep`]) for one work item: per band, the
//! running maximum of its window values over the lines at least L ahead of the current one
//! (fed through a ring that delays each line's values by L − 1 steps), the line where that
//! maximum lies, and a history of the maxima of each block of [`BLOCK`] consecutive lines and
//! of each super-block of [`SUPER`] blocks.
//!
//! **Why the history.** A pixel whose band maximum does not clear the bound, and whose
//! witness in the maximum's line is lit, used to be handed to the accelerated traversal
//! (about 1.4 µs each at 4096², sun 5°: a ray that grazes a distant ridge descends the mipmap
//! there). With the history its lines are settled where they are: a super-block or block whose
//! maximum clears the bound holds no texel above the ray; every line of the other blocks gets
//! the exact test ([`crate::terrain::hard::sweep`]).
//! Every line beyond the first L is then either bounded or tested, so the answer stays exact.
//!
//! Entry s·nq + (q − q0) is band j = K·q + s. Values are computed in f64 and kept as f32 no
//! smaller ([`up_f32`], at most four f32 ulps above): the bands stay upper bounds, so every
//! "lit" they prove still holds, and a value can only send more pixels to the exact tests.
//! Four lanes per SSE instruction instead of two, and half the memory (the history: 512 KiB
//! for a work item's 512 bands over 4096 lines).

/// Lines per history block.
pub const BLOCK: usize = 16;
/// Blocks per super-block: a pixel settled line by line first skips the super-blocks whose
/// maximum clears the bound (about 16 of them at 4096 lines instead of 256 blocks).
pub const SUPER: usize = 16;

/// The bands of one work item ([`crate::terrain::hard::sweep`]).
pub struct Bands {
    pub q0: i64,
    pub nq: usize,
    /// Per band: the maximum over the lines at least L ahead, and the line where it lies.
    pub best2: Vec<f32>,
    pub row2: Vec<u32>,
    /// The ring of the last L − 1 lines' values (slot-major), and each slot's line.
    prev: Vec<f32>,
    prev_row: Vec<u32>,
    /// Per band, the maxima of the finished blocks (band-major, `blocks` per band) and of the
    /// block being filled.
    hist: Vec<f32>,
    blocks: usize,
    /// Per band, the maxima of the super-blocks (band-major, [`Bands::sups`] per band): the
    /// running maximum of their finished blocks.
    sup: Vec<f32>,
    cur: Vec<f32>,
    steps: usize,
}

impl Bands {
    /// `nb` bands (K·nq) from q0, a ring of `slots` = L − 1 lines, a map of `steps` lines.
    pub fn new(q0: i64, nq: usize, k: usize, slots: usize, steps: usize) -> Bands {
        let n = k * nq;
        let blocks = steps.div_ceil(BLOCK);
        Bands {
            q0,
            nq,
            best2: vec![f32::NEG_INFINITY; n],
            row2: vec![u32::MAX; n],
            prev: vec![f32::NEG_INFINITY; slots * n],
            prev_row: vec![u32::MAX; slots],
            hist: vec![f32::NEG_INFINITY; n * blocks],
            blocks,
            sup: vec![f32::NEG_INFINITY; n * blocks.div_ceil(SUPER)],
            cur: vec![f32::NEG_INFINITY; n],
            steps,
        }
    }

    /// Step `step` (canonical line `y`): for sub-band s, `wmax[q − q0]` is the window maximum
    /// of g = D − rise·c·u in this line. The ring's oldest line joins `best2`, this line's
    /// values take its slot and its block's maximum.
    pub fn push(&mut self, step: usize, s: usize, wmax: &[f32]) {
        let (nq, slots) = (self.nq, self.prev_row.len());
        let slot = step % slots;
        let n = self.best2.len();
        let r = s * nq..(s + 1) * nq;
        let pr = slot * n + s * nq..slot * n + (s + 1) * nq;
        let (best2, row2) = (&mut self.best2[r.clone()], &mut self.row2[r.clone()]);
        let (prev, cur) = (&mut self.prev[pr], &mut self.cur[r]);
        let prev_row = self.prev_row[slot];
        // Zipped slices of one length and selects instead of branches: with f32 values and u32
        // rows (the same lane width) this vectorises, four bands per SSE instruction.
        let lanes = best2
            .iter_mut()
            .zip(row2.iter_mut())
            .zip(prev.iter_mut().zip(cur.iter_mut()))
            .zip(&wmax[..nq]);
        for (((b, r), (p, c)), &v) in lanes {
            let older = *p;
            // All ones where the ring's oldest value beats the best (a bit mask, so that the
            // compiler keeps both stores unconditional).
            let take = 0u32.wrapping_sub((older > *b) as u32);
            *b = f32::from_bits((b.to_bits() & !take) | (older.to_bits() & take));
            *r = (*r & !take) | (prev_row & take);
            *p = v;
            *c = if v > *c { v } else { *c };
        }
    }

    /// After every sub-band of step `step` (line `y`) was pushed.
    pub fn end_step(&mut self, step: usize, y: usize) {
        let slots = self.prev_row.len();
        self.prev_row[step % slots] = y as u32;
        if (step + 1).is_multiple_of(BLOCK) || step + 1 == self.steps {
            let (b, sups) = (step / BLOCK, self.sups());
            for (i, c) in self.cur.iter_mut().enumerate() {
                self.hist[i * self.blocks + b] = *c;
                let s = &mut self.sup[i * sups + b / SUPER];
                *s = if *c > *s { *c } else { *s };
                *c = f32::NEG_INFINITY;
            }
        }
    }

    /// The maxima of band entry i's first `n` blocks (each finished).
    pub fn blocks(&self, i: usize, n: usize) -> &[f32] {
        &self.hist[i * self.blocks..][..n]
    }

    /// The maxima of band entry i's first `n` super-blocks (each of whose blocks finished).
    pub fn supers(&self, i: usize, n: usize) -> &[f32] {
        &self.sup[i * self.sups()..][..n]
    }

    /// Super-blocks per band.
    fn sups(&self) -> usize {
        self.blocks.div_ceil(SUPER)
    }
}

/// An f32 no smaller than the finite `v`, and at most 2⁻²²·|v| + 2e-30 above it (four f32
/// ulps): `v` raised by 2⁻²³ of its magnitude and 1e-30 in f64, then rounded to nearest, which
/// moves it by at most half an f32 ulp, 2⁻²⁴ of the magnitude (f64's own rounding, 2⁻⁵³, is
/// far below the difference). Branch-free, so a row of it vectorises.
#[inline(always)]
pub fn up_f32(v: f64) -> f32 {
    (v + v.abs() * (1.0 / 8_388_608.0) + 1e-30) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// `up_f32` never lowers a value and raises it by at most 2⁻²²·|v| + 2e-30, at every
        /// magnitude from 1e-35 to 1e30 and at exact f32 values (where rounding is idle).
        #[test]
        fn up_f32_bounds_from_above(m in -1.0f64..1.0, e in -35i32..=30, exact in proptest::bool::ANY) {
            let v = if exact { (m * 10f64.powi(e)) as f32 as f64 } else { m * 10f64.powi(e) };
            let f = up_f32(v) as f64;
            proptest::prop_assert!(f >= v, "{} -> {}", v, f);
            proptest::prop_assert!(f - v <= v.abs() / 4_194_304.0 + 2e-30, "{} -> {}", v, f);
        }
    }

    #[test]
    fn blocks_hold_the_maxima_of_their_lines() {
        // One band (k = 1, nq = 1), ring of 1, 40 lines: block b's maximum is the largest of
        // lines b·16 .. b·16 + 15, whatever the ring does.
        let mut bands = Bands::new(0, 1, 1, 1, 40);
        let vals: Vec<f32> = (0..40).map(|i| ((i * 37) % 23) as f32 - 0.1).collect();
        for (step, &v) in vals.iter().enumerate() {
            bands.push(step, 0, &[v]);
            bands.end_step(step, step);
        }
        let blocks = bands.blocks(0, 3);
        for (b, &m) in blocks.iter().enumerate() {
            let want = vals[b * BLOCK..((b + 1) * BLOCK).min(40)]
                .iter()
                .fold(f32::NEG_INFINITY, |a, &v| a.max(v));
            assert_eq!(m, want, "block {b}");
        }
        // 40 lines make 3 blocks, all in super-block 0, which is not finished (16 blocks).
        assert_eq!(bands.supers(0, 0).len(), 0);
        assert_eq!(
            bands.sup[0],
            blocks.iter().fold(f32::NEG_INFINITY, |a, &v| a.max(v))
        );
        // best2 holds every line but the last (the ring delays by one).
        let want = vals[..39].iter().fold(f32::NEG_INFINITY, |a, &v| a.max(v));
        assert_eq!(bands.best2[0], want);
    }
}
