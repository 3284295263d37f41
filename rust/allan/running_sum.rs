//! The compensated running sum behind the cumulative phase, chunk by chunk.
//!
//! Each chunk of [`CHUNK`] values is one dependency chain (every step adds to
//! the sum of the step before), so a chunk alone waits on the latency of each
//! addition. With AVX-512 (detected at run time) eight chunks advance together,
//! one in each lane, doing per lane exactly the scalar steps below: the results
//! are the same bits on either path, eight times fewer waits on the vector one.

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
                if group.len() == LANES * CHUNK && avx512() {
                    // SAFETY: the CPU has AVX-512F (checked just above).
                    return unsafe { x86::group_totals(group, mean) }.to_vec();
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
            #[cfg(target_arch = "x86_64")]
            {
                if group.len() == LANES * CHUNK && avx512() {
                    // SAFETY: the CPU has AVX-512F (checked just above).
                    return unsafe { x86::group_run(group, starts, mean) };
                }
            }
            for (chunk, &start) in group.chunks_mut(CHUNK).zip(starts) {
                scalar_run(chunk, start, mean);
            }
        });
}

/// The scalar chain over one chunk from (0, 0): its (sum, error).
fn scalar_total(chunk: &[f64], mean: f64) -> (f64, f64) {
    chunk
        .iter()
        .fold((0.0, 0.0), |acc, &v| compensated_step(acc, v - mean))
}

/// The scalar chain over one chunk from `start`, each value replaced by the
/// running sum.
fn scalar_run(chunk: &mut [f64], start: (f64, f64), mean: f64) {
    let mut acc = start;
    for value in chunk.iter_mut() {
        acc = compensated_step(acc, *value - mean);
        *value = acc.0 + acc.1;
    }
}

#[cfg(target_arch = "x86_64")]
fn avx512() -> bool {
    crate::simd::level() >= crate::simd::Level::Avx512
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use std::arch::x86_64::*;

    use super::{CHUNK, LANES};

    /// Lane l reads chunk l: element i of the group's chunks at offsets l·CHUNK + i.
    #[inline(always)]
    unsafe fn chunk_offsets() -> __m512i {
        let c = CHUNK as i64;
        _mm512_setr_epi64(0, c, 2 * c, 3 * c, 4 * c, 5 * c, 6 * c, 7 * c)
    }

    /// [`super::compensated_step`] in every lane (the same operations in the same
    /// order: no fused multiply-add, no reassociation).
    #[inline(always)]
    unsafe fn step(sum: __m512d, comp: __m512d, v: __m512d) -> (__m512d, __m512d) {
        let t = _mm512_add_pd(sum, v);
        let bp = _mm512_sub_pd(t, sum);
        let err = _mm512_add_pd(
            _mm512_sub_pd(sum, _mm512_sub_pd(t, bp)),
            _mm512_sub_pd(v, bp),
        );
        (t, _mm512_add_pd(comp, err))
    }

    /// The totals of the eight chunks of `group` (exactly `LANES · CHUNK` values).
    #[target_feature(enable = "avx512f")]
    pub unsafe fn group_totals(group: &[f64], mean: f64) -> [(f64, f64); LANES] {
        assert_eq!(group.len(), LANES * CHUNK);
        let offsets = chunk_offsets();
        let m = _mm512_set1_pd(mean);
        let (mut sum, mut comp) = (_mm512_setzero_pd(), _mm512_setzero_pd());
        for i in 0..CHUNK {
            // SAFETY: i + l·CHUNK < LANES·CHUNK = group.len() for every lane l.
            let v = _mm512_i64gather_pd::<8>(offsets, group.as_ptr().add(i).cast());
            (sum, comp) = step(sum, comp, _mm512_sub_pd(v, m));
        }
        let (mut s, mut c) = ([0.0f64; LANES], [0.0f64; LANES]);
        _mm512_storeu_pd(s.as_mut_ptr(), sum);
        _mm512_storeu_pd(c.as_mut_ptr(), comp);
        std::array::from_fn(|l| (s[l], c[l]))
    }

    /// The running sums of the eight chunks of `group` from `starts`, in place.
    #[target_feature(enable = "avx512f")]
    pub unsafe fn group_run(group: &mut [f64], starts: &[(f64, f64)], mean: f64) {
        assert!(group.len() == LANES * CHUNK && starts.len() == LANES);
        let offsets = chunk_offsets();
        let m = _mm512_set1_pd(mean);
        let s: [f64; LANES] = std::array::from_fn(|l| starts[l].0);
        let c: [f64; LANES] = std::array::from_fn(|l| starts[l].1);
        let (mut sum, mut comp) = (_mm512_loadu_pd(s.as_ptr()), _mm512_loadu_pd(c.as_ptr()));
        for i in 0..CHUNK {
            // SAFETY: i + l·CHUNK < LANES·CHUNK = group.len() for every lane l.
            let at = group.as_mut_ptr().add(i);
            let v = _mm512_i64gather_pd::<8>(offsets, at.cast_const().cast());
            (sum, comp) = step(sum, comp, _mm512_sub_pd(v, m));
            _mm512_i64scatter_pd::<8>(at.cast(), offsets, _mm512_add_pd(sum, comp));
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
            scalar_run(chunk, start, mean);
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
        let fast_totals = chunk_totals(&values, mean);
        assert_eq!(fast_totals.len(), totals.len());
        for (a, b) in fast_totals.iter().zip(&totals) {
            assert_eq!(
                (a.0.to_bits(), a.1.to_bits()),
                (b.0.to_bits(), b.1.to_bits())
            );
        }
        let starts: Vec<(f64, f64)> = (0..totals.len())
            .map(|k| (k as f64 * 0.5, k as f64 * 1e-17))
            .collect();
        let mut fast_run = values.clone();
        run_chunks(&mut fast_run, &starts, mean);
        assert!(fast_run
            .iter()
            .zip(&run)
            .all(|(a, b)| a.to_bits() == b.to_bits()));
    }
}
