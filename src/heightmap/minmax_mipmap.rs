//! The min/max mipmap (docs/algorithms.md §4; the relief-shadow paper's {h_max, h_min} mipmap): the acceleration
//! structure of the accelerated hard-shadow traversal and of the soft-shadow methods.
//!
//! Level 0 is half the map's size (rounded up): texel (bx, by) bounds block
//! [2bx, 2bx+2) × [2by, 2by+2) of the height map. Level L halves level L−1 (rounded up) with 2×2
//! max/min reductions, so a level-L texel bounds the block of side B_L = 2^(L+1) texels starting
//! at (bx·B_L, by·B_L). Levels stop before 1×1 (a map whose level 0 would be 1×1 has no levels).
//! Odd and non-power-of-two sizes: edge blocks reduce the children (and texels) that exist.
//!
//! **Bounds.** Level 0 stores the max and min of the texels in the block *plus a one-texel
//! border* (the 4×4 texels [2bx−1, 2bx+2] × [2by−1, 2by+2], clamped to the map) — the footprint
//! of the relief-shadow paper's 3×3 pattern of bilinear samples, with texel values instead of averages. Why
//! this is conservative for every value the exact traversal samples in the block: a sample of
//! texel T is taken at a point Q clamped into T's square, and `terrain::hard::exact_traversal::sample_bilinear` clamps its
//! result to the range of the four texels of Q's bilinear cell; for Q in T's square those four
//! texels lie within one texel of T (border-clamped), hence inside the block's bordered
//! footprint. So every sample h satisfies min ≤ h ≤ max, exactly, in floating point (no
//! rounding is involved in a min/max of f32 values); `tests/terrain/exactness.rs` checks it with
//! proptest. The bound is looser than the exact range of bilinear values (which would need
//! averages and outward rounding to stay provable) only next to a block's border.
//!
//! **Flat layout** (what the GPU uploads): `data` holds 2 f32 per texel, `max` then `min`, levels
//! one after another; texel (bx, by) of level L is at `2 · (levels[L].offset + by · levels[L].width + bx)`.

use crate::heightmap::HeightMap;
use rayon::prelude::*;

/// The size and place of one level in [`MinMaxMipmap::data`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MipLevel {
    pub width: usize,
    pub height: usize,
    /// Index of the level's first texel (in texels, not floats).
    pub offset: usize,
}

/// Min/max mipmap of a height map.
#[derive(Clone, Debug, PartialEq)]
pub struct MinMaxMipmap {
    /// Size of the height map it was built from.
    pub map_width: usize,
    pub map_height: usize,
    pub levels: Vec<MipLevel>,
    /// (max, min) pairs, level after level, row-major.
    pub data: Vec<f32>,
    /// The largest height of the map (the maximum over the coarsest level).
    pub max_height: f32,
    /// The smallest height of the map (the minimum over the coarsest level).
    pub min_height: f32,
}

/// The level sizes for a map: ceil(W/2) × ceil(H/2), then ceil halving, stopping before 1×1
/// (level 0 always exists, 1×1 for maps of at most 2×2).
pub fn level_sizes(width: usize, height: usize) -> Vec<(usize, usize)> {
    let (mut w, mut h) = (width.div_ceil(2), height.div_ceil(2));
    let mut out = vec![(w, h)];
    loop {
        w = w.div_ceil(2);
        h = h.div_ceil(2);
        if w == 1 && h == 1 {
            return out;
        }
        out.push((w, h));
    }
}

impl MinMaxMipmap {
    /// Build the mipmap of `map` (parallel over rows; the result does not depend on threads).
    pub fn build(map: &HeightMap) -> MinMaxMipmap {
        let sizes = level_sizes(map.width, map.height);
        let mut levels = Vec::with_capacity(sizes.len());
        let mut offset = 0;
        for &(width, height) in &sizes {
            levels.push(MipLevel {
                width,
                height,
                offset,
            });
            offset += width * height;
        }
        let mut data = vec![0.0f32; 2 * offset];
        if let Some(l0) = levels.first() {
            let (w, h) = (map.width, map.height);
            let hs = &map.heights;
            data[..2 * l0.width * l0.height]
                .par_chunks_mut(2 * l0.width)
                .enumerate()
                .for_each(|(by, row)| {
                    let y0 = (2 * by).saturating_sub(1);
                    let y1 = (2 * by + 2).min(h - 1);
                    for bx in 0..l0.width {
                        let x0 = (2 * bx).saturating_sub(1);
                        let x1 = (2 * bx + 2).min(w - 1);
                        let (mut hi, mut lo) = (f32::NEG_INFINITY, f32::INFINITY);
                        for y in y0..=y1 {
                            for &v in &hs[y * w + x0..=y * w + x1] {
                                hi = hi.max(v);
                                lo = lo.min(v);
                            }
                        }
                        row[2 * bx] = hi;
                        row[2 * bx + 1] = lo;
                    }
                });
        }
        for l in 1..levels.len() {
            let (prev, cur) = (levels[l - 1], levels[l]);
            let (done, rest) = data.split_at_mut(2 * cur.offset);
            let src = &done[2 * prev.offset..];
            rest[..2 * cur.width * cur.height]
                .par_chunks_mut(2 * cur.width)
                .enumerate()
                .for_each(|(by, row)| {
                    for bx in 0..cur.width {
                        let (mut hi, mut lo) = (f32::NEG_INFINITY, f32::INFINITY);
                        for y in 2 * by..(2 * by + 2).min(prev.height) {
                            for x in 2 * bx..(2 * bx + 2).min(prev.width) {
                                let i = 2 * (y * prev.width + x);
                                hi = hi.max(src[i]);
                                lo = lo.min(src[i + 1]);
                            }
                        }
                        row[2 * bx] = hi;
                        row[2 * bx + 1] = lo;
                    }
                });
        }
        let (max_height, min_height) = top_max_min(&levels, &data);
        MinMaxMipmap {
            map_width: map.width,
            map_height: map.height,
            levels,
            data,
            max_height,
            min_height,
        }
    }

    /// (max, min) of texel (bx, by) of `level`.
    #[inline]
    pub fn texel(&self, level: usize, bx: usize, by: usize) -> (f32, f32) {
        let l = &self.levels[level];
        let i = 2 * (l.offset + by * l.width + bx);
        (self.data[i], self.data[i + 1])
    }

    /// Side of the block of height-map texels a texel of `level` bounds (without the border).
    pub fn block_size(level: usize) -> usize {
        2 << level
    }

    /// (max, min) bounding every sample with x index in `xs` and y index in `ys` (inclusive,
    /// clamped to the map): the max/min of at most 2×2 texels of the finest level whose blocks
    /// cover the rectangle in two per axis. Conservative, never tighter than the samples' range.
    pub fn sample_range(&self, xs: (usize, usize), ys: (usize, usize)) -> (f32, f32) {
        let clamp =
            |r: (usize, usize), n: usize| (r.0.min(n - 1), r.1.min(n - 1).max(r.0.min(n - 1)));
        let (x0, x1) = clamp(xs, self.map_width);
        let (y0, y1) = clamp(ys, self.map_height);
        for (l, level) in self.levels.iter().enumerate() {
            let b = Self::block_size(l);
            let (bx0, bx1, by0, by1) = (x0 / b, x1 / b, y0 / b, y1 / b);
            if bx1 - bx0 <= 1 && by1 - by0 <= 1 {
                let (mut hi, mut lo) = (f32::NEG_INFINITY, f32::INFINITY);
                for by in by0..=by1.min(level.height - 1) {
                    for bx in bx0..=bx1.min(level.width - 1) {
                        let (h, l) = self.texel(l, bx, by);
                        hi = hi.max(h);
                        lo = lo.min(l);
                    }
                }
                return (hi, lo);
            }
        }
        (self.max_height, self.min_height)
    }

    /// Bytes of the texel data (f32 pairs).
    pub fn bytes(&self) -> usize {
        self.data.len() * 4
    }
}

pub fn top_max_min(levels: &[MipLevel], data: &[f32]) -> (f32, f32) {
    let top = levels.last().expect("level 0 always exists");
    data[2 * top.offset..2 * (top.offset + top.width * top.height)]
        .chunks_exact(2)
        .fold((f32::NEG_INFINITY, f32::INFINITY), |(hi, lo), p| {
            (hi.max(p[0]), lo.min(p[1]))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_sizes_round_up_and_stop_before_one_by_one() {
        assert_eq!(level_sizes(8, 8), vec![(4, 4), (2, 2)]);
        assert_eq!(level_sizes(2, 2), vec![(1, 1)]);
        assert_eq!(level_sizes(1, 1), vec![(1, 1)]);
        assert_eq!(level_sizes(5, 1), vec![(3, 1), (2, 1)]);
        assert_eq!(level_sizes(1197, 643).len(), 10);
        assert_eq!(level_sizes(4096, 4096).len(), 11);
    }

    #[test]
    fn level_zero_includes_a_one_texel_border() {
        // A single peak at (2, 0) is inside block 1 and in the border of block 0.
        let mut h = vec![0.0f32; 6 * 2];
        h[2] = 5.0;
        let m = MinMaxMipmap::build(&HeightMap::new(6, 2, h, [1.0, 1.0]));
        assert_eq!(m.levels.len(), 2);
        assert_eq!(m.texel(0, 0, 0), (5.0, 0.0));
        assert_eq!(m.texel(0, 1, 0), (5.0, 0.0));
        assert_eq!(m.texel(0, 2, 0), (0.0, 0.0));
        assert_eq!(m.texel(1, 1, 0), (0.0, 0.0));
    }
}
