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

/// Sum of absolute differences with eight accumulators (vectorises; the summation order of
/// `radiosity::transport::matrix::sum_pairs8`).
#[inline]
pub fn l1(a: &[f32], b: &[f32]) -> f32 {
    crate::radiosity::transport::matrix::sum_pairs8(a, b, |x, y| (x - y).abs())
}
