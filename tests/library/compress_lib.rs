//! Compression library: exactness, extremes, laws.
#![allow(clippy::needless_range_loop)]

use crate::transport_box;

use proptest::prelude::*;
use relume::compress::report::{self, rms_relative, standard_lights};
use relume::compress::{
    compress, gather, reorder, split_top, DenseEncoding, EncodeOptions, ReorderMetric,
    ReorderOptions, Sidecar,
};
use relume::radiosity::transport::matrix::is_permutation;
use relume::radiosity::TransportMatrix;

fn opts(encoding: DenseEncoding) -> EncodeOptions {
    EncodeOptions {
        encoding,
        ..Default::default()
    }
}

fn identity(n: usize) -> Vec<u32> {
    (0..n as u32).collect()
}

/// A small matrix with a smooth, wide-dynamic-range structure.
fn smooth(ch: usize, n: usize) -> TransportMatrix {
    let mut data = Vec::with_capacity(ch * n * n);
    for c in 0..ch {
        for i in 0..n {
            for j in 0..n {
                let d = (i as f32 - j as f32).abs() + 1.0;
                data.push(
                    0.3 / (d * d) * (1.0 + 0.2 * c as f32) + 1e-5 * ((i * 7 + j * 3) % 11) as f32,
                );
            }
        }
    }
    TransportMatrix::new(ch, n, data).unwrap()
}

#[test]
fn zero_matrix_decodes_to_exact_zero_in_every_encoding() {
    for ch in [1, 3] {
        let s = TransportMatrix::zeros(ch, 9);
        for enc in DenseEncoding::ALL {
            for feedback in [false, true] {
                let o = EncodeOptions {
                    feedback,
                    ..opts(enc)
                };
                let e = compress(&s, identity(9), 4.0, &o).unwrap();
                let r = report::entry_errors(&s, &e);
                assert_eq!((r.sum, r.max), (0.0, 0.0), "{enc:?} ch {ch} fb {feedback}");
                let b = gather(&e, &vec![1.0; ch * 9]);
                assert!(b.iter().all(|v| v.to_bits() == 0), "{enc:?}: {b:?}");
            }
        }
    }
}

#[test]
fn zero_blocks_stay_exactly_zero_next_to_nonzero_blocks() {
    // Left half of the matrix is zero: those blocks are all-zero and must decode to exactly 0.
    let n = 16;
    let mut s = smooth(3, n);
    for c in 0..3 {
        for i in 0..n {
            for j in 0..8 {
                s.data[(c * n + i) * n + j] = 0.0;
            }
        }
    }
    for enc in DenseEncoding::ALL {
        let e = compress(&s, identity(n), 0.0, &opts(enc)).unwrap();
        let dec = e.dense.decoder();
        let mut vals = [[0.0f32; 16]; 3];
        for by in 0..4 {
            for bx in 0..2 {
                dec.block(by, bx, &mut vals);
                assert!(
                    vals.iter().flatten().all(|v| *v == 0.0),
                    "{enc:?} block {by},{bx}"
                );
            }
        }
    }
}

#[test]
fn sidecar_entries_are_bit_exact_and_survive_serialisation() {
    let s = smooth(3, 37);
    let (dense, side) = split_top(&s, 8.0).unwrap();
    assert_eq!(side.nnz(), (0.08f64 * 37.0 * 37.0).round() as usize);
    for i in 0..37 {
        for k in side.row_ptr[i] as usize..side.row_ptr[i + 1] as usize {
            let j = side.cols[k] as usize;
            for c in 0..3 {
                assert_eq!(side.values[k * 3 + c].to_bits(), s.get(c, i, j).to_bits());
                assert_eq!(dense.get(c, i, j), 0.0);
            }
        }
    }
    // The sidecar holds the largest entries: none left in the dense part is bigger.
    let smallest_side = side
        .values
        .chunks(3)
        .map(|v| v.iter().cloned().fold(0.0, f32::max))
        .fold(f32::MAX, f32::min);
    let largest_dense = dense.data.iter().cloned().fold(0.0, f32::max);
    assert!(largest_dense <= smallest_side);
    let bytes = side.to_bytes();
    assert_eq!(bytes.len(), side.byte_len());
    let back = Sidecar::from_bytes(std::path::Path::new("sidecar.bin"), &bytes).unwrap();
    assert_eq!(back, side);
    // A corrupted header is an input error naming the file.
    let mut bad = bytes.clone();
    bad[20] ^= 1;
    let err = Sidecar::from_bytes(std::path::Path::new("x/sidecar.bin"), &bad).unwrap_err();
    assert!(err.to_string().contains("x/sidecar.bin"), "{err}");
}

#[test]
fn split_ties_are_broken_by_index() {
    let s = TransportMatrix::new(1, 4, vec![1.0; 16]).unwrap();
    let (_, side) = split_top(&s, 25.0).unwrap();
    // Four equal entries: the first four in row-major order.
    assert_eq!(side.cols, vec![0, 1, 2, 3]);
    assert_eq!(side.row_ptr, vec![0, 4, 4, 4, 4]);
}

#[test]
fn p_zero_and_p_hundred() {
    let s = smooth(3, 21);
    let light = standard_lights(3, 21);
    let exact = s.mat_vec(&light[1].1);
    let e0 = compress(&s, identity(21), 0.0, &opts(DenseEncoding::Bc1Log)).unwrap();
    assert_eq!(e0.sidecar.nnz(), 0);
    let e100 = compress(&s, identity(21), 100.0, &opts(DenseEncoding::Bc1Log)).unwrap();
    assert_eq!(e100.sidecar.nnz(), 21 * 21);
    assert!(e100.dense.maps.iter().all(|m| m.scale == 0.0));
    let r = report::entry_errors(&s, &e100);
    assert_eq!(r.max, 0.0, "everything in the sidecar is exact");
    let b = gather(&e100, &light[1].1);
    assert!(rms_relative(&b, &exact) < 1e-6);
}

#[test]
fn one_huge_entry_among_tiny_ones() {
    let n = 24;
    let mut s = TransportMatrix::new(
        1,
        n,
        (0..n * n).map(|k| 1e-6 * (1.0 + (k % 5) as f32)).collect(),
    )
    .unwrap();
    s.data[5 * n + 17] = 1e6;
    // Without a split the tiny entries fall below e^-25 of the huge one and are dropped...
    let e0 = compress(&s, identity(n), 0.0, &opts(DenseEncoding::Bc4Log)).unwrap();
    let r0 = report::entry_errors(&s, &e0);
    assert!(r0.max <= 1e6 * 0.06, "{r0:?}");
    // ...with the smallest split the huge entry is exact (zeroed in the dense part, as in the radiosity thesis)...
    let e = compress(&s, identity(n), 0.1, &opts(DenseEncoding::Bc4Log)).unwrap();
    assert_eq!(e.sidecar.nnz(), 1);
    assert_eq!(e.sidecar.values[0], 1e6);
    let r = report::entry_errors(&s, &e);
    assert!(r.max <= 5e-6, "{r:?}");
    // ...and with hole filling the zeroed entry no longer spoils its block: the tiny ones keep
    // the log map's precision.
    let fill = EncodeOptions {
        fill_holes: true,
        ..opts(DenseEncoding::Bc4Log)
    };
    let e = compress(&s, identity(n), 0.1, &fill).unwrap();
    let r = report::entry_errors(&s, &e);
    assert!(r.max < 5e-6 * 0.15, "{r:?}");
    assert!(
        (e.sidecar.values[0] - 1e6).abs() <= 1e-5,
        "{}",
        e.sidecar.values[0]
    );
    for enc in DenseEncoding::ALL {
        let e = compress(&s, identity(n), 0.1, &opts(enc)).unwrap();
        let b = gather(&e, &vec![1.0; n]);
        let exact = s.mat_vec(&vec![1.0; n]);
        assert!(rms_relative(&b, &exact) < 1e-6, "{enc:?}");
    }
}

const TOL_F16: f64 = 6e-4;
const TOL_BC6H: f64 = 0.23;
const TOL_BC1: f64 = 0.23;
const TOL_BC4: f64 = 0.33;

/// Largest RMS relative gather error over n = 1, 3, 5, both channel counts and the standard
/// lights, measured per encoding (`cargo test --release --test library compress_lib:: padding -- --nocapture`
/// prints them): F32 0, F16 1.48e-4, BC6H 5.82e-2, BC1-log 5.72e-2, BC4-log 8.18e-2.
/// The tolerances allow 4x that (F32: exact up to f32 summation order).
fn padding_tolerance(enc: DenseEncoding) -> f64 {
    match enc {
        DenseEncoding::F32 => 1e-6,
        DenseEncoding::F16 => TOL_F16,
        DenseEncoding::Bc6h => TOL_BC6H,
        DenseEncoding::Bc1Log => TOL_BC1,
        DenseEncoding::Bc4Log => TOL_BC4,
    }
}

#[test]
fn padding_for_n_1_3_5() {
    for enc in DenseEncoding::ALL {
        let mut worst: f64 = 0.0;
        for n in [1usize, 3, 5] {
            for ch in [1, 3] {
                let s = smooth(ch, n);
                let e = compress(&s, identity(n), 0.0, &opts(enc)).unwrap();
                assert_eq!(e.dense.padded, 4 * n.div_ceil(4));
                e.dense.validate().unwrap();
                for (name, light) in standard_lights(ch, n) {
                    let exact = s.mat_vec(&light);
                    let b = gather(&e, &light);
                    let err = rms_relative(&b, &exact);
                    worst = worst.max(err);
                    assert!(
                        err <= padding_tolerance(enc),
                        "n {n} ch {ch} {enc:?} {name}: error {err} ({b:?} vs {exact:?})"
                    );
                }
            }
        }
        eprintln!("padding: {enc:?} worst RMS relative error {worst:.3e}");
    }
}

#[test]
fn gather_from_permuted_compressed_matrix_is_within_the_reported_error() {
    let scene = transport_box::closed_box(6, 3);
    let s = transport_box::transport(&scene, Some(3));
    let n = s.n;
    let perm = reorder(
        &mut s.clone(),
        ReorderOptions {
            passes: 2,
            metric: ReorderMetric::Linear,
            ..Default::default()
        },
    );
    assert!(is_permutation(&perm));
    let sp = s.permuted(&perm);
    let lights = transport_box::box_lights(&scene);
    for enc in DenseEncoding::ALL {
        let e = compress(&sp, perm.clone(), 4.0, &opts(enc)).unwrap();
        let rep = report::report(&s, &sp, &e, &lights);
        for (name, light) in &lights {
            let exact = s.mat_vec(light);
            let b = gather(&e, light);
            // |B̃_i − B_i| = |Σ_j δ_ij E_j| ≤ (Σ_j |δ_ij|) max E ≤ sum_abs_error · max E.
            let emax = light.iter().cloned().fold(0.0, f32::max) as f64;
            for k in 0..3 * n {
                let d = (b[k] as f64 - exact[k] as f64).abs();
                assert!(
                    d <= rep.entry.sum * emax * (1.0 + 1e-4) + 1e-5 * exact[k] as f64,
                    "{enc:?} {name} {k}"
                );
            }
            let r = rep.gather_rms_rel.iter().find(|x| &x.0 == name).unwrap().1;
            assert_eq!(r, rms_relative(&b, &exact));
            if enc == DenseEncoding::F32 {
                assert!(r < 1e-5, "{name}: {r}");
            }
        }
    }
}

#[test]
fn two_reorder_passes_do_not_increase_the_summed_error() {
    let s = transport_box::transport_or_env(12, Some(3));
    let mut sums = Vec::new();
    for passes in 0..=2 {
        let perm = reorder(
            &mut s.clone(),
            ReorderOptions {
                passes,
                metric: ReorderMetric::Linear,
                ..Default::default()
            },
        );
        let sp = s.permuted(&perm);
        let e = compress(&sp, perm, 4.0, &opts(DenseEncoding::Bc1Log)).unwrap();
        sums.push(report::entry_errors(&sp, &e).sum);
    }
    eprintln!("summed error, passes 0/1/2: {sums:?}");
    assert!(sums[2] <= sums[0], "{sums:?}");
}

#[test]
fn encoding_is_deterministic_across_thread_counts() {
    let s = smooth(3, 30);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let perm = reorder(
                &mut s.clone(),
                ReorderOptions {
                    passes: 2,
                    metric: ReorderMetric::Log,
                    ..Default::default()
                },
            );
            let sp = s.permuted(&perm);
            let e = compress(&sp, perm, 4.0, &opts(DenseEncoding::Bc1Log)).unwrap();
            let r = report::report(&s, &sp, &e, &standard_lights(3, 30));
            (e, r)
        })
    };
    assert_eq!(run(1), run(3));
}

fn matrix_strategy() -> impl Strategy<Value = TransportMatrix> {
    (prop_oneof![Just(1usize), Just(3usize)], 1usize..14).prop_flat_map(|(ch, n)| {
        prop::collection::vec(
            prop_oneof![Just(0.0f32), 1e-9f32..1.0f32, 1e-3f32..10.0f32],
            ch * n * n,
        )
        .prop_map(move |d| TransportMatrix::new(ch, n, d).unwrap())
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn permutation_is_a_bijection_and_s_prime_is_p_s_pt(s in matrix_strategy(), passes in 0u8..=2, log in any::<bool>()) {
        let metric = if log { ReorderMetric::Log } else { ReorderMetric::Linear };
        let perm = reorder(&mut s.clone(), ReorderOptions {
            passes,
            metric,
            ..Default::default()
        });
        prop_assert!(is_permutation(&perm));
        prop_assert_eq!(perm.len(), s.n);
        let sp = s.permuted(&perm);
        for c in 0..s.channels {
            for k in 0..s.n {
                for l in 0..s.n {
                    prop_assert_eq!(sp.get(c, k, l).to_bits(), s.get(c, perm[k] as usize, perm[l] as usize).to_bits());
                }
            }
        }
        // The gather through the permutation is the product with S (F32: exact up to rounding).
        let e = compress(&sp, perm, 0.0, &opts(DenseEncoding::F32)).unwrap();
        for (_, light) in standard_lights(s.channels, s.n) {
            let exact = s.mat_vec(&light);
            prop_assert!(rms_relative(&gather(&e, &light), &exact) < 1e-5);
        }
    }

    #[test]
    fn decoded_values_are_bounded(s in matrix_strategy(), p in 0.0f64..20.0) {
        let (dense, _) = split_top(&s, p).unwrap();
        for enc in DenseEncoding::ALL {
            let e = compress(&s, identity(s.n), p, &opts(enc)).unwrap();
            let dec = e.dense.decoder();
            let mut vals = [[0.0f32; 16]; 3];
            let bw = e.dense.padded / 4;
            for by in 0..bw {
                for bx in 0..bw {
                    dec.block(by, bx, &mut vals);
                    for c in 0..s.channels {
                        let nn = s.n * s.n;
                        let scale = dense.data[c * nn..(c + 1) * nn].iter().cloned().fold(0.0f32, f32::max);
                        for t in 0..16 {
                            let v = vals[c][t];
                            prop_assert!(v.is_finite() && v >= 0.0, "{:?} {}", enc, v);
                            // Never above the channel's largest dense value (F16: rounding).
                            // BC6H makes no such promise: on blocks mixing zeros with values
                            // decades apart its quantised endpoints overshoot.
                            if enc != DenseEncoding::Bc6h {
                                prop_assert!(v <= scale * 1.002 + f32::MIN_POSITIVE, "{:?} {} > {}", enc, v, scale);
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn log_map_round_trip_is_within_half_a_step(x in 1e-9f32..1.0, scale in 1.0f32..100.0) {
        let m = relume::compress::logmap::LogMap::seed(scale);
        let v = x * scale;
        let back = m.decode(m.encode(v));
        let half_step = ((25.0f64 / 255.0 / 2.0).exp() - 1.0) * 1.0001;
        prop_assert!(((back as f64) - v as f64).abs() <= half_step * v as f64, "{} -> {}", v, back);
    }
}

/// The split's selection by brute force: every entry's key (largest magnitude over the
/// channels, NaN ignored, infinite as f32::MAX), sorted by (magnitude descending, index), the
/// first k, as (row, column) in row-major order.
fn top_by_sorting(s: &TransportMatrix, percent: f64) -> Vec<(usize, usize)> {
    let (n, ch) = (s.n, s.channels);
    let k = relume::compress::split::split_count(n, percent);
    let mut keys: Vec<(u32, usize)> = (0..n * n)
        .map(|ij| {
            let mag = (0..ch).fold(0.0f32, |a, c| a.max(s.data[c * n * n + ij].abs()));
            let mag = if mag.is_finite() { mag } else { f32::MAX };
            (!mag.to_bits(), ij)
        })
        .collect();
    keys.sort_unstable();
    let mut top: Vec<usize> = keys[..k].iter().map(|e| e.1).collect();
    top.sort_unstable();
    top.into_iter().map(|ij| (ij / n, ij % n)).collect()
}

fn sidecar_positions(side: &Sidecar) -> Vec<(usize, usize)> {
    (0..side.n)
        .flat_map(|i| side.row_cols(i).iter().map(move |&j| (i, j as usize)))
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// The split's histogram selection keeps exactly the entries a full sort keeps, ties (many
    /// here) to the lower index, with zeros, infinities and NaN among the values.
    #[test]
    fn split_selects_what_a_full_sort_selects(
        (ch, n) in (prop_oneof![Just(1usize), Just(3usize)], 1usize..24),
        seed in any::<u64>(),
        percent in prop_oneof![Just(0.0f64), Just(100.0f64), 0.0f64..100.0],
    ) {
        let pool = [0.0f32, 0.5, 1.0, 2.0, -1.0, f32::INFINITY, f32::NAN, 1e-30];
        let mut x = seed | 1;
        let data = (0..ch * n * n)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                pool[(x % pool.len() as u64) as usize]
            })
            .collect();
        let s = TransportMatrix::new(ch, n, data).unwrap();
        let (_, side) = split_top(&s, percent).unwrap();
        prop_assert_eq!(sidecar_positions(&side), top_by_sorting(&s, percent));
    }
}

/// The selection over several chunks of 2¹⁸ entries, with the k-th key in a tie class that
/// spans them: the lowest indices of the class are taken, across the chunk boundary.
#[test]
fn split_ties_across_chunks_go_to_the_lower_index() {
    let n = 700;
    let data = (0..n * n)
        .map(|ij| ((ij * 7 + ij / n * 13) % 5) as f32)
        .collect();
    let s = TransportMatrix::new(1, n, data).unwrap();
    for percent in [0.01, 19.9, 30.0, 61.3, 99.9] {
        let (_, side) = split_top(&s, percent).unwrap();
        assert_eq!(
            sidecar_positions(&side),
            top_by_sorting(&s, percent),
            "{percent} %"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// With hole filling, `compress` encodes the whole permuted matrix with the sidecar's
    /// entries counting as zero: the same texture as encoding the dense part with those
    /// entries zeroed (the copy it no longer makes), in every encoding.
    #[test]
    fn hole_filling_encodes_as_the_zeroed_dense_part(
        s in matrix_strategy(),
        percent in 0.0f64..30.0,
        encoding in prop_oneof![
            Just(DenseEncoding::Bc6h),
            Just(DenseEncoding::Bc1Log),
            Just(DenseEncoding::Bc4Log),
            Just(DenseEncoding::F16),
        ],
    ) {
        let o = EncodeOptions { fill_holes: true, ..opts(encoding) };
        let enc = compress(&s, identity(s.n), percent, &o).unwrap();
        let (dense_part, side) = split_top(&s, percent).unwrap();
        let want = relume::compress::encode::encode_dense(&dense_part, &o, Some(&side)).unwrap();
        prop_assert!(enc.dense == want);
        prop_assert_eq!(sidecar_positions(&enc.sidecar), sidecar_positions(&side));
    }
}

/// A row split off whole (every entry in the sidecar) has no texel that matters to copy from:
/// hole filling must see it as the zeroed dense part does, not as its original values.
#[test]
fn a_row_split_off_whole_encodes_as_zeros() {
    let n = 5;
    let data = (0..n * n)
        .map(|ij| {
            if ij / n == 0 {
                100.0 + ij as f32
            } else {
                0.01 * (1 + ij % 3) as f32
            }
        })
        .collect();
    let s = TransportMatrix::new(1, n, data).unwrap();
    for encoding in [
        DenseEncoding::Bc6h,
        DenseEncoding::Bc4Log,
        DenseEncoding::F16,
    ] {
        let o = EncodeOptions {
            fill_holes: true,
            ..opts(encoding)
        };
        let enc = compress(&s, identity(n), 20.0, &o).unwrap();
        let (dense_part, side) = split_top(&s, 20.0).unwrap();
        assert_eq!(side.row_cols(0).len(), n, "row 0 is the sidecar");
        let want = relume::compress::encode::encode_dense(&dense_part, &o, Some(&side)).unwrap();
        assert!(enc.dense == want, "{encoding:?}");
    }
}
