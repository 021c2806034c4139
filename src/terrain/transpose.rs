//! Transposing a row-major grid in cache-sized tiles: the hard-shadow sweep and the horizon
//! sweep both walk lines along one axis and transpose the map for the others.

use rayon::prelude::*;

/// Transpose a w×h row-major grid. Tiles of 64×64 go through a buffer in L1: each tile's 64
/// source rows are read and its 64 destination rows written as whole runs, so no access walks
/// a column with the map's stride (a 4096-wide map's rows are 16 KiB apart, and a column of
/// them maps onto one set of the L1 cache: the previous 32×32 blocking thrashed it, 52 ms
/// against 12 ms for this at 4096², docs/terrain.md).
pub fn transpose(src: &[f32], w: usize, h: usize) -> Vec<f32> {
    transpose_map(src, w, h, |&x| x)
}

/// [`transpose`] with `f` applied to every element on the way: `dst[x·h + y] = f(src[y·w + x])`,
/// in 64 × 64 tiles (a column of the source read whole would touch one cache line per element).
pub fn transpose_map<S, D>(src: &[S], w: usize, h: usize, f: impl Fn(&S) -> D + Sync) -> Vec<D>
where
    S: Sync,
    D: Copy + Default + Send,
{
    const T: usize = 64;
    let mut dst = vec![D::default(); w * h];
    // dst is h wide and w tall: dst[x * h + y] = f(src[y * w + x]).
    dst.par_chunks_mut(h * T).enumerate().for_each(|(bx, out)| {
        let x0 = bx * T;
        let xs = out.len() / h;
        let mut tile = [[D::default(); T]; T];
        for y0 in (0..h).step_by(T) {
            let ys = T.min(h - y0);
            for (dy, t) in tile[..ys].iter_mut().enumerate() {
                for (t, s) in t[..xs].iter_mut().zip(&src[(y0 + dy) * w + x0..][..xs]) {
                    *t = f(s);
                }
            }
            for dx in 0..xs {
                let o = &mut out[dx * h + y0..][..ys];
                for (dy, o) in o.iter_mut().enumerate() {
                    *o = tile[dy][dx];
                }
            }
        }
    });
    dst
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transpose_swaps_axes() {
        let src: Vec<f32> = (0..35).map(|i| i as f32).collect();
        let t = transpose(&src, 7, 5);
        for y in 0..5 {
            for x in 0..7 {
                assert_eq!(t[x * 5 + y], src[y * 7 + x]);
            }
        }
    }
}
