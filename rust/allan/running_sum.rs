//! The compensated running sum behind the cumulative phase, chunk by chunk.
//!
//! Each chunk of [`CHUNK`] values is one dependency chain (every step adds to
//! the sum of the step before), so a chunk alone waits on the latency of each
//! addition. With AVX2 or AVX-512 (detected at run time) eight chunks advance
//! together, one in each lane (two vectors of four with AVX2), doing per lane
//! exactly the scalar steps below: the results are the same bits on every path,
//! eight times fewer waits on the vector ones. The lanes read and write their
//! chunks by tiles: eight (four) consecutive values of each chunk are loaded and
//! transposed in registers, so that a vector holds one step of every chunk
//! (a gather per step, and a scatter to write it back, cost more than the
//! scalar chain).

use std::mem::MaybeUninit;

use rayon::prelude::*;

/// Values per chunk. Fixed (not derived from the thread count), so the result is
/// the same on any machine; a record of one chunk is transformed exactly as by
/// a single sequential pass.
pub const CHUNK: usize = 1 << 16;

/// Chunks that advance together on the vector path.
const LANES: usize = 8;

/// Knuth's branch-free two-sum: a + b = t + err exactly.
#[inline(always)]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let t = a + b;
    let bp = t - a;
    (t, (a - (t - bp)) + (b - bp))
}

/// One step of the compensated running sum: the sum and the accumulated rounding
/// errors form two independent dependency chains.
#[inline(always)]
fn compensated_step((sum, comp): (f64, f64), v: f64) -> (f64, f64) {
    let (t, err) = two_sum(sum, v);
    (t, comp + err)
}

/// Each chunk's total of `v − mean` over `values` as (sum, error), from (0, 0).
pub fn chunk_totals(values: &[f64], mean: f64) -> Vec<(f64, f64)> {
    values
        .par_chunks(LANES * CHUNK)
        .flat_map_iter(|group| {
            #[cfg(target_arch = "x86_64")]
            {
                if group.len() == LANES * CHUNK {
                    // SAFETY: each kernel runs only at a level the CPU has.
                    match vector_level() {
                        Some(Vector::Avx512) => {
                            return unsafe { x86::group_totals_avx512(group, mean) }.to_vec()
                        }
                        Some(Vector::Avx2) => {
                            return unsafe { x86::group_totals_avx2(group, mean) }.to_vec()
                        }
                        None => {}
                    }
                }
            }
            group
                .chunks(CHUNK)
                .map(|chunk| scalar_total(chunk, mean))
                .collect::<Vec<_>>()
        })
        .collect()
}

/// Replaces each value v of `values` by the running compensated sum of `v − mean`,
/// chunk k starting from `starts[k]` (one pair per chunk).
pub fn run_chunks(values: &mut [f64], starts: &[(f64, f64)], mean: f64) {
    values
        .par_chunks_mut(LANES * CHUNK)
        .zip(starts.par_chunks(LANES))
        .for_each(|(group, starts)| {
            let at = group.as_mut_ptr();
            // SAFETY: the group is read and written in place through one pointer.
            unsafe { group_run(at, at, group.len(), starts, mean) }
        });
}

/// [`run_chunks`] from `values` into `out` (as long), which is written entirely:
/// a gap-free record's phase is written once, in this pass, instead of a copy
/// of the samples transformed in place.
pub fn run_chunks_into(
    values: &[f64],
    out: &mut [MaybeUninit<f64>],
    starts: &[(f64, f64)],
    mean: f64,
) {
    assert_eq!(values.len(), out.len());
    out.par_chunks_mut(LANES * CHUNK)
        .zip(values.par_chunks(LANES * CHUNK))
        .zip(starts.par_chunks(LANES))
        .for_each(|((out, group), starts)| {
            // SAFETY: `group` and `out` are distinct, equally long slices.
            unsafe {
                group_run(
                    group.as_ptr(),
                    out.as_mut_ptr().cast(),
                    group.len(),
                    starts,
                    mean,
                )
            }
        });
}

/// The running sums of a group of up to `LANES` chunks of `len` values at `src`,
/// written to `dst` (which may be `src`).
///
/// # Safety
/// `src` must be valid for reading and `dst` for writing `len` values, and
/// `starts` must hold one pair per chunk.
unsafe fn group_run(src: *const f64, dst: *mut f64, len: usize, starts: &[(f64, f64)], mean: f64) {
    #[cfg(target_arch = "x86_64")]
    {
        if len == LANES * CHUNK {
            // SAFETY: each kernel runs only at a level the CPU has.
            match vector_level() {
                Some(Vector::Avx512) => return x86::group_run_avx512(src, dst, starts, mean),
                Some(Vector::Avx2) => return x86::group_run_avx2(src, dst, starts, mean),
                None => {}
            }
        }
    }
    for (k, &start) in starts.iter().enumerate().take(len.div_ceil(CHUNK)) {
        let at = k * CHUNK;
        scalar_run(src.add(at), dst.add(at), CHUNK.min(len - at), start, mean);
    }
}

/// The scalar chain over one chunk from (0, 0): its (sum, error).
fn scalar_total(chunk: &[f64], mean: f64) -> (f64, f64) {
    chunk
        .iter()
        .fold((0.0, 0.0), |acc, &v| compensated_step(acc, v - mean))
}

/// The scalar chain over one chunk of `len` values from `start`: each value
/// read at `src`, its running sum written at `dst` (which may be `src`).
///
/// # Safety
/// As [`group_run`].
unsafe fn scalar_run(src: *const f64, dst: *mut f64, len: usize, start: (f64, f64), mean: f64) {
    let mut acc = start;
    for i in 0..len {
        acc = compensated_step(acc, *src.add(i) - mean);
        *dst.add(i) = acc.0 + acc.1;
    }
}

/// The vector kernels a level may run.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
enum Vector {
    Avx2,
    Avx512,
}

#[cfg(target_arch = "x86_64")]
fn vector_level() -> Option<Vector> {
    use crate::simd::{level, Level};
    match level() {
        Level::Scalar => None,
        Level::Avx2 => Some(Vector::Avx2),
        Level::Avx512 | Level::Ifma => Some(Vector::Avx512),
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::{CHUNK, LANES};

    /// [`super::compensated_step`] in every lane (the same operations in the same
    /// order: no fused multiply-add, no reassociation).
    #[inline(always)]
    unsafe fn step512(sum: __m512d, comp: __m512d, v: __m512d) -> (__m512d, __m512d) {
        let t = _mm512_add_pd(sum, v);
        let bp = _mm512_sub_pd(t, sum);
        let err = _mm512_add_pd(
            _mm512_sub_pd(sum, _mm512_sub_pd(t, bp)),
            _mm512_sub_pd(v, bp),
        );
        (t, _mm512_add_pd(comp, err))
    }

    /// The 8 × 8 transpose: `out[j][l] = rows[l][j]`.
    #[inline(always)]
    unsafe fn transpose8(r: [__m512d; 8]) -> [__m512d; 8] {
        // Pairs of rows interleaved within 128-bit lanes.
        let a0 = _mm512_unpacklo_pd(r[0], r[1]);
        let a1 = _mm512_unpackhi_pd(r[0], r[1]);
        let a2 = _mm512_unpacklo_pd(r[2], r[3]);
        let a3 = _mm512_unpackhi_pd(r[2], r[3]);
        let a4 = _mm512_unpacklo_pd(r[4], r[5]);
        let a5 = _mm512_unpackhi_pd(r[4], r[5]);
        let a6 = _mm512_unpacklo_pd(r[6], r[7]);
        let a7 = _mm512_unpackhi_pd(r[6], r[7]);
        // Quadruples of rows: elements 0, 4 (lo) or 2, 6 (hi) of a0 with a2.
        let lo = _mm512_setr_epi64(0, 1, 8, 9, 4, 5, 12, 13);
        let hi = _mm512_setr_epi64(2, 3, 10, 11, 6, 7, 14, 15);
        let b0 = _mm512_permutex2var_pd(a0, lo, a2); // columns 0 | 4, rows 0–3
        let b1 = _mm512_permutex2var_pd(a0, hi, a2); // columns 2 | 6
        let b2 = _mm512_permutex2var_pd(a1, lo, a3); // columns 1 | 5
        let b3 = _mm512_permutex2var_pd(a1, hi, a3); // columns 3 | 7
        let b4 = _mm512_permutex2var_pd(a4, lo, a6); // rows 4–7
        let b5 = _mm512_permutex2var_pd(a4, hi, a6);
        let b6 = _mm512_permutex2var_pd(a5, lo, a7);
        let b7 = _mm512_permutex2var_pd(a5, hi, a7);
        // Rows 0–3 beside rows 4–7: the low halves give columns 0–3, the high 4–7.
        [
            _mm512_shuffle_f64x2::<0x44>(b0, b4),
            _mm512_shuffle_f64x2::<0x44>(b2, b6),
            _mm512_shuffle_f64x2::<0x44>(b1, b5),
            _mm512_shuffle_f64x2::<0x44>(b3, b7),
            _mm512_shuffle_f64x2::<0xEE>(b0, b4),
            _mm512_shuffle_f64x2::<0xEE>(b2, b6),
            _mm512_shuffle_f64x2::<0xEE>(b1, b5),
            _mm512_shuffle_f64x2::<0xEE>(b3, b7),
        ]
    }

    /// The eight values at `i..i + 8` of each chunk of `group`, as steps: vector
    /// j holds value i + j of every chunk.
    #[inline(always)]
    unsafe fn load_steps512(group: *const f64, i: usize) -> [__m512d; 8] {
        transpose8(std::array::from_fn(|l| {
            _mm512_loadu_pd(group.add(l * CHUNK + i))
        }))
    }

    /// The totals of the eight chunks of `group` (exactly `LANES · CHUNK` values).
    #[target_feature(enable = "avx512f")]
    pub unsafe fn group_totals_avx512(group: &[f64], mean: f64) -> [(f64, f64); LANES] {
        assert_eq!(group.len(), LANES * CHUNK);
        let m = _mm512_set1_pd(mean);
        let (mut sum, mut comp) = (_mm512_setzero_pd(), _mm512_setzero_pd());
        for i in (0..CHUNK).step_by(8) {
            // SAFETY: l·CHUNK + i + 8 ≤ LANES·CHUNK = group.len() for every lane l.
            for v in load_steps512(group.as_ptr(), i) {
                (sum, comp) = step512(sum, comp, _mm512_sub_pd(v, m));
            }
        }
        let (mut s, mut c) = ([0.0f64; LANES], [0.0f64; LANES]);
        _mm512_storeu_pd(s.as_mut_ptr(), sum);
        _mm512_storeu_pd(c.as_mut_ptr(), comp);
        std::array::from_fn(|l| (s[l], c[l]))
    }

    /// The running sums of the eight chunks at `src` from `starts`, written to
    /// `dst` (`LANES · CHUNK` values each; `dst` may be `src`).
    #[target_feature(enable = "avx512f")]
    pub unsafe fn group_run_avx512(
        src: *const f64,
        dst: *mut f64,
        starts: &[(f64, f64)],
        mean: f64,
    ) {
        assert_eq!(starts.len(), LANES);
        let m = _mm512_set1_pd(mean);
        let s: [f64; LANES] = std::array::from_fn(|l| starts[l].0);
        let c: [f64; LANES] = std::array::from_fn(|l| starts[l].1);
        let (mut sum, mut comp) = (_mm512_loadu_pd(s.as_ptr()), _mm512_loadu_pd(c.as_ptr()));
        for i in (0..CHUNK).step_by(8) {
            // SAFETY: as in group_totals_avx512; a tile is read before it is written.
            let steps = load_steps512(src, i);
            let mut out = [_mm512_setzero_pd(); 8];
            for (o, v) in out.iter_mut().zip(steps) {
                (sum, comp) = step512(sum, comp, _mm512_sub_pd(v, m));
                *o = _mm512_add_pd(sum, comp);
            }
            for (l, row) in transpose8(out).into_iter().enumerate() {
                _mm512_storeu_pd(dst.add(l * CHUNK + i), row);
            }
        }
    }

    /// [`step512`] on four lanes.
    #[inline(always)]
    unsafe fn step256(sum: __m256d, comp: __m256d, v: __m256d) -> (__m256d, __m256d) {
        let t = _mm256_add_pd(sum, v);
        let bp = _mm256_sub_pd(t, sum);
        let err = _mm256_add_pd(
            _mm256_sub_pd(sum, _mm256_sub_pd(t, bp)),
            _mm256_sub_pd(v, bp),
        );
        (t, _mm256_add_pd(comp, err))
    }

    /// The 4 × 4 transpose: `out[j][l] = rows[l][j]`.
    #[inline(always)]
    unsafe fn transpose4(r: [__m256d; 4]) -> [__m256d; 4] {
        let a0 = _mm256_unpacklo_pd(r[0], r[1]); // r0[0] r1[0] r0[2] r1[2]
        let a1 = _mm256_unpackhi_pd(r[0], r[1]); // r0[1] r1[1] r0[3] r1[3]
        let a2 = _mm256_unpacklo_pd(r[2], r[3]);
        let a3 = _mm256_unpackhi_pd(r[2], r[3]);
        [
            _mm256_permute2f128_pd::<0x20>(a0, a2),
            _mm256_permute2f128_pd::<0x20>(a1, a3),
            _mm256_permute2f128_pd::<0x31>(a0, a2),
            _mm256_permute2f128_pd::<0x31>(a1, a3),
        ]
    }

    /// Values `i..i + 4` of chunks `first..first + 4` of `group` as steps.
    #[inline(always)]
    unsafe fn load_steps256(group: *const f64, first: usize, i: usize) -> [__m256d; 4] {
        transpose4(std::array::from_fn(|l| {
            _mm256_loadu_pd(group.add((first + l) * CHUNK + i))
        }))
    }

    /// [`group_totals_avx512`] as two chains of four lanes (chunks 0–3, 4–7).
    #[target_feature(enable = "avx2")]
    pub unsafe fn group_totals_avx2(group: &[f64], mean: f64) -> [(f64, f64); LANES] {
        assert_eq!(group.len(), LANES * CHUNK);
        let m = _mm256_set1_pd(mean);
        let zero = _mm256_setzero_pd();
        let (mut sum, mut comp) = ([zero; 2], [zero; 2]);
        for i in (0..CHUNK).step_by(4) {
            // SAFETY: (first + l)·CHUNK + i + 4 ≤ LANES·CHUNK = group.len().
            let low = load_steps256(group.as_ptr(), 0, i);
            let high = load_steps256(group.as_ptr(), 4, i);
            for (a, b) in low.into_iter().zip(high) {
                (sum[0], comp[0]) = step256(sum[0], comp[0], _mm256_sub_pd(a, m));
                (sum[1], comp[1]) = step256(sum[1], comp[1], _mm256_sub_pd(b, m));
            }
        }
        let (mut s, mut c) = ([0.0f64; LANES], [0.0f64; LANES]);
        for h in 0..2 {
            _mm256_storeu_pd(s.as_mut_ptr().add(4 * h), sum[h]);
            _mm256_storeu_pd(c.as_mut_ptr().add(4 * h), comp[h]);
        }
        std::array::from_fn(|l| (s[l], c[l]))
    }

    /// [`group_run_avx512`] as two chains of four lanes (chunks 0–3, 4–7).
    #[target_feature(enable = "avx2")]
    pub unsafe fn group_run_avx2(src: *const f64, dst: *mut f64, starts: &[(f64, f64)], mean: f64) {
        assert_eq!(starts.len(), LANES);
        let m = _mm256_set1_pd(mean);
        let s: [f64; LANES] = std::array::from_fn(|l| starts[l].0);
        let c: [f64; LANES] = std::array::from_fn(|l| starts[l].1);
        let mut sum = [
            _mm256_loadu_pd(s.as_ptr()),
            _mm256_loadu_pd(s.as_ptr().add(4)),
        ];
        let mut comp = [
            _mm256_loadu_pd(c.as_ptr()),
            _mm256_loadu_pd(c.as_ptr().add(4)),
        ];
        for i in (0..CHUNK).step_by(4) {
            // SAFETY: as in group_totals_avx2; a tile is read before it is written.
            let steps = [load_steps256(src, 0, i), load_steps256(src, 4, i)];
            let mut out = [[_mm256_setzero_pd(); 4]; 2];
            for j in 0..4 {
                for h in 0..2 {
                    (sum[h], comp[h]) = step256(sum[h], comp[h], _mm256_sub_pd(steps[h][j], m));
                    out[h][j] = _mm256_add_pd(sum[h], comp[h]);
                }
            }
            for (h, out) in out.into_iter().enumerate() {
                for (l, row) in transpose4(out).into_iter().enumerate() {
                    _mm256_storeu_pd(dst.add((4 * h + l) * CHUNK + i), row);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scalar chain over every chunk: the definition both paths must equal.
    fn reference(values: &[f64], mean: f64) -> (Vec<(f64, f64)>, Vec<f64>) {
        let totals: Vec<(f64, f64)> = values
            .chunks(CHUNK)
            .map(|c| scalar_total(c, mean))
            .collect();
        let starts: Vec<(f64, f64)> = (0..totals.len())
            .map(|k| (k as f64 * 0.5, k as f64 * 1e-17))
            .collect();
        let mut run = values.to_vec();
        for (chunk, &start) in run.chunks_mut(CHUNK).zip(&starts) {
            let at = chunk.as_mut_ptr();
            // SAFETY: the chunk is read and written in place.
            unsafe { scalar_run(at, at, chunk.len(), start, mean) };
        }
        (totals, run)
    }

    #[test]
    fn vector_and_scalar_chains_give_the_same_bits() {
        // Two full groups of eight chunks and a partial one; values spanning many
        // magnitudes so that the error terms matter.
        let n = 2 * LANES * CHUNK + 3 * CHUNK + 1234;
        let values: Vec<f64> = crate::allan::test_signals::noise(n, 0x2545_F491_4F6C_DD1D)
            .into_iter()
            .enumerate()
            .map(|(k, u)| u * 10f64.powi((k % 17) as i32 - 8) + 9.81)
            .collect();
        let mean = 9.81;
        let (totals, run) = reference(&values, mean);
        crate::simd::at_every_level(|_| check_paths(&values, mean, &totals, &run));
    }

    fn check_paths(values: &[f64], mean: f64, totals: &[(f64, f64)], run: &[f64]) {
        let fast_totals = chunk_totals(values, mean);
        assert_eq!(fast_totals.len(), totals.len());
        for (a, b) in fast_totals.iter().zip(totals) {
            assert_eq!(
                (a.0.to_bits(), a.1.to_bits()),
                (b.0.to_bits(), b.1.to_bits())
            );
        }
        let starts: Vec<(f64, f64)> = (0..totals.len())
            .map(|k| (k as f64 * 0.5, k as f64 * 1e-17))
            .collect();
        let mut fast_run = values.to_vec();
        run_chunks(&mut fast_run, &starts, mean);
        assert!(fast_run
            .iter()
            .zip(run)
            .all(|(a, b)| a.to_bits() == b.to_bits()));
        let mut into = vec![MaybeUninit::new(f64::NAN); values.len()];
        run_chunks_into(values, &mut into, &starts, mean);
        assert!(into
            .iter()
            .zip(run)
            .all(|(a, b)| unsafe { a.assume_init() }.to_bits() == b.to_bits()));
    }
}
