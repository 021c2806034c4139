//! L1 distances of f32 vectors in one fixed summation order (eight accumulators within chunks
//! of `KCHUNK` coordinates, chunks added in order), shared by the full and the bounded greedy
//! reorder so that both find the same order bit for bit.

/// Coordinates per chunk of a distance (cache blocking; part of the summation order).
pub const KCHUNK: usize = 512;

/// The L1 distance of two whole vectors exactly as `reorder::pairwise_l1` sums it: chunks of
/// `KCHUNK` coordinates, each by [`l1`], added in order.
pub fn l1_chunked(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = 0.0f32;
    for (ca, cb) in a.chunks(KCHUNK).zip(b.chunks(KCHUNK)) {
        acc += l1(ca, cb);
    }
    acc
}

/// Sum of absolute differences with eight accumulators (vectorises).
#[inline]
pub fn l1(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [0.0f32; 8];
    let ca = a.chunks_exact(8);
    let cb = b.chunks_exact(8);
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..8 {
            acc[l] += (x[l] - y[l]).abs();
        }
    }
    let mut s = 0.0f32;
    for (x, y) in ra.iter().zip(rb) {
        s += (x - y).abs();
    }
    ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7])) + s
}
