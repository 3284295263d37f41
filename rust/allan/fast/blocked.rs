//! Overlapping Allan and Hadamard variances at many taus in one sweep.
//!
//! Evaluating one tau at a time streams the whole cumulative phase through
//! memory two or three times per tau. Here the start index k advances in blocks
//! of a few thousand samples and every tau is evaluated on the block before
//! moving on, so a window of the phase read for one tau (c[k + 2m…] for the
//! Allan variance) is still in cache when the next, longer tau needs it (as
//! c[k + m'…] with m' = 2m on an octave grid). Memory traffic falls by a factor
//! of about three, and that is what bounds these sums. Super-blocks run in
//! parallel; the partial sums are added in order with compensation, so the
//! result does not depend on the number of threads.

use rayon::prelude::*;

use crate::allan::sum::{column_totals, sum_of_squared_combinations, Neumaier};
use crate::interrupt::Interrupt;

/// Samples per block: three windows of every short tau stay in L1/L2.
const BLOCK: usize = 2048;
/// Blocks per parallel task.
const BLOCKS_PER_TASK: usize = 64;

/// Order of the difference: 2 (Allan, weights 1 −2 1) or 3 (Hadamard, 1 −3 3 −1).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Difference {
    Second,
    Third,
}

impl Difference {
    fn span(self) -> usize {
        match self {
            Difference::Second => 2,
            Difference::Third => 3,
        }
    }
}

/// Σ_k (d-th difference of c at lag m, starting at k)² for every m in `ms`, over
/// k = 0..N − d·m (all overlapping terms). Averaging factors that do not fit give 0.
/// Meaningless once `stop` is raised (each task of a few milliseconds checks it).
pub fn sums_of_squares(
    c: &[f64],
    ms: &[usize],
    difference: Difference,
    stop: &Interrupt,
) -> Vec<f64> {
    let span = difference.span();
    let terms: Vec<usize> = ms
        .iter()
        .map(|&m| c.len().saturating_sub(span * m))
        .collect();
    let sweep = Sweep {
        c,
        ms,
        terms: &terms,
        difference,
    };
    let longest = terms.iter().copied().max().unwrap_or(0);
    let task_len = BLOCK * BLOCKS_PER_TASK;
    let tasks = longest.div_ceil(task_len);
    let partials: Vec<Vec<f64>> = (0..tasks)
        .into_par_iter()
        .map(|task| {
            if stop.raised() {
                return vec![0.0; ms.len()];
            }
            let start = task * task_len;
            sweep.task_sums(start, (start + task_len).min(longest))
        })
        .collect();
    column_totals(&partials, ms.len())
}

/// One sweep: the phase, its averaging factors and their term counts.
struct Sweep<'a> {
    c: &'a [f64],
    ms: &'a [usize],
    terms: &'a [usize],
    difference: Difference,
}

impl Sweep<'_> {
    /// The sums over start indices start..end, compiled for AVX2 where the CPU has
    /// it: the sweep is bound by arithmetic once blocked, and AVX2 doubles the
    /// lanes of the portable SSE2 build.
    fn task_sums(&self, start: usize, end: usize) -> Vec<f64> {
        #[cfg(target_arch = "x86_64")]
        {
            if crate::simd::level() >= crate::simd::Level::Avx2 {
                // SAFETY: the CPU supports AVX2 (the level never exceeds the CPU's).
                return unsafe { self.task_sums_avx2(start, end) };
            }
        }
        self.task_sums_portable(start, end)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn task_sums_avx2(&self, start: usize, end: usize) -> Vec<f64> {
        self.task_sums_portable(start, end)
    }

    #[inline(always)]
    fn task_sums_portable(&self, start: usize, end: usize) -> Vec<f64> {
        let c = self.c;
        let mut acc = vec![Neumaier::new(); self.ms.len()];
        let mut k0 = start;
        while k0 < end {
            let k1 = (k0 + BLOCK).min(end);
            for (j, &m) in self.ms.iter().enumerate() {
                let stop = k1.min(self.terms[j]);
                if stop <= k0 {
                    continue;
                }
                let len = stop - k0;
                let window = |lag: usize| &c[k0 + lag..k0 + lag + len];
                let s = match self.difference {
                    Difference::Second => sum_of_squared_combinations(
                        [window(2 * m), window(m), window(0)],
                        [1.0, -2.0, 1.0],
                    ),
                    Difference::Third => sum_of_squared_combinations(
                        [window(3 * m), window(2 * m), window(m), window(0)],
                        [1.0, -3.0, 3.0, -1.0],
                    ),
                };
                acc[j].add(s);
            }
            k0 = k1;
        }
        acc.iter().map(Neumaier::value).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::Statistic;

    #[test]
    fn blocked_sums_match_one_tau_at_a_time() {
        let n = 3 * BLOCK * BLOCKS_PER_TASK + 123;
        let mut c = vec![0.0];
        for k in 0..n {
            let y = ((k * 7919) % 1013) as f64 / 1013.0 - 0.5;
            c.push(c[k] + y);
        }
        let ms = [1, 2, 3, 64, 1000, 5000, n / 3];
        for (difference, statistic, divisor) in [
            (
                Difference::Second,
                Statistic::Allan { overlapping: true },
                2.0,
            ),
            (
                Difference::Third,
                Statistic::Hadamard { overlapping: true },
                6.0,
            ),
        ] {
            let sums = sums_of_squares(&c, &ms, difference, &crate::interrupt::NEVER);
            for (j, &m) in ms.iter().enumerate() {
                let one = statistic.estimate(&c, m, &crate::interrupt::NEVER);
                let blocked = sums[j] / (divisor * (m * m) as f64 * one.terms as f64);
                assert!(
                    (blocked / one.var - 1.0).abs() < 1e-13,
                    "m={m}: {blocked} vs {}",
                    one.var
                );
            }
        }
    }
}
