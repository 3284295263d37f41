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

use crate::allan::sum::{column_totals, Neumaier};
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
    sweep_sums(c, ms, difference, stop, |m| {
        m >= COLUMN && m.is_multiple_of(COLUMN)
    })
}

/// [`sums_of_squares`] with the factors that `by_column` picks swept by columns.
fn sweep_sums(
    c: &[f64],
    ms: &[usize],
    difference: Difference,
    stop: &Interrupt,
    by_column: impl Fn(usize) -> bool,
) -> Vec<f64> {
    let span = difference.span();
    let terms: Vec<usize> = ms
        .iter()
        .map(|&m| c.len().saturating_sub(span * m))
        .collect();
    let by_column: Vec<bool> = ms.iter().map(|&m| by_column(m)).collect();
    let sweep = Sweep {
        c,
        ms,
        terms: &terms,
        by_column: &by_column,
        difference,
        two: std::hint::black_box(2.0),
    };
    let longest = terms.iter().copied().max().unwrap_or(0);
    let task_len = BLOCK * BLOCKS_PER_TASK;
    let tasks = longest.div_ceil(task_len);
    let (mut partials, block_sums) = rayon::join(
        || {
            (0..tasks)
                .into_par_iter()
                .map(|task| {
                    if stop.raised() {
                        return vec![0.0; ms.len()];
                    }
                    let start = task * task_len;
                    sweep.task_sums(start, (start + task_len).min(longest))
                })
                .collect::<Vec<Vec<f64>>>()
        },
        || sweep.column_block_sums(stop),
    );
    // The factors swept by columns: their block sums added as a task adds them.
    for (j, sums) in block_sums {
        for (task, row) in partials.iter_mut().enumerate() {
            let blocks = (task * BLOCKS_PER_TASK).min(sums.len())
                ..((task + 1) * BLOCKS_PER_TASK).min(sums.len());
            row[j] = sums[blocks].iter().sum::<Neumaier>().value();
        }
    }
    column_totals(&partials, ms.len())
}

/// Long averaging factors that are multiples of `COLUMN` are swept by columns: a
/// block of start indices k0 and its windows c[k0 + m…], c[k0 + 2m…] (and
/// c[k0 + 3m…]) then lie in the same column, the blocks at k0 mod `COLUMN`.
/// The sweep by tasks reads each such window again when it reaches it after
/// megabytes of other windows, from memory (a few passes over the phase for the
/// longest octave taus, half the sweep's time); a column of a 10⁷-point phase is
/// 2.4 MB and is read once for all of them.
const COLUMN: usize = 1 << 16;

/// One sweep: the phase, its averaging factors and their term counts.
struct Sweep<'a> {
    c: &'a [f64],
    ms: &'a [usize],
    terms: &'a [usize],
    /// Factors swept by columns (`COLUMN`), left out of the tasks.
    by_column: &'a [bool],
    difference: Difference,
    /// 2.0, hidden from the optimiser: it would turn 2·x into x + x, which is the
    /// same bits but puts a fourth addition per term on the two adders, while the
    /// multipliers idle (the sweep is bound by its additions).
    two: f64,
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
        let mut acc = vec![Neumaier::new(); self.ms.len()];
        let mut k0 = start;
        while k0 < end {
            let k1 = (k0 + BLOCK).min(end);
            for (j, acc) in acc.iter_mut().enumerate() {
                if self.by_column[j] {
                    continue;
                }
                if let Some(s) = self.block_sum(j, k0, k1) {
                    acc.add(s);
                }
            }
            k0 = k1;
        }
        acc.iter().map(Neumaier::value).collect()
    }

    /// The squares of factor j's terms k0..k1 (cut at its last term), if any.
    #[inline(always)]
    fn block_sum(&self, j: usize, k0: usize, k1: usize) -> Option<f64> {
        let (c, m) = (self.c, self.ms[j]);
        let stop = k1.min(self.terms[j]);
        if stop <= k0 {
            return None;
        }
        let len = stop - k0;
        let window = |lag: usize| &c[k0 + lag..k0 + lag + len];
        Some(match self.difference {
            Difference::Second => {
                second_difference_squares([window(2 * m), window(m), window(0)], self.two)
            }
            Difference::Third => {
                third_difference_squares([window(3 * m), window(2 * m), window(m), window(0)])
            }
        })
    }

    /// Each factor swept by columns, with the sums of its blocks of `BLOCK`
    /// start indices in order (the values the tasks' blocks would give).
    /// Columns run in parallel; within one, the blocks advance together for
    /// every factor. Meaningless once `stop` is raised.
    fn column_block_sums(&self, stop: &Interrupt) -> Vec<(usize, Vec<f64>)> {
        let factors: Vec<usize> = (0..self.ms.len()).filter(|&j| self.by_column[j]).collect();
        let Some(longest) = factors.iter().map(|&j| self.terms[j]).max() else {
            return Vec::new();
        };
        let blocks = longest.div_ceil(BLOCK);
        let stride = COLUMN / BLOCK;
        let columns: Vec<Vec<Option<f64>>> = (0..stride.min(blocks))
            .into_par_iter()
            .map(|column| {
                if stop.raised() {
                    return Vec::new();
                }
                self.column_sums(&factors, column, stride, blocks)
            })
            .collect();
        factors
            .iter()
            .enumerate()
            .map(|(f, &j)| {
                let sums: Vec<f64> = (0..self.terms[j].div_ceil(BLOCK))
                    .map(|b| {
                        let at = (b / stride) * factors.len() + f;
                        columns[b % stride]
                            .get(at)
                            .copied()
                            .flatten()
                            .unwrap_or(0.0)
                    })
                    .collect();
                (j, sums)
            })
            .collect()
    }

    /// The block sums of one column (blocks column, column + stride, …), block
    /// by block and factor by factor; compiled for AVX2 as [`Self::task_sums`].
    fn column_sums(
        &self,
        factors: &[usize],
        column: usize,
        stride: usize,
        blocks: usize,
    ) -> Vec<Option<f64>> {
        #[cfg(target_arch = "x86_64")]
        {
            if crate::simd::level() >= crate::simd::Level::Avx2 {
                // SAFETY: the CPU supports AVX2 (the level never exceeds the CPU's).
                return unsafe { self.column_sums_avx2(factors, column, stride, blocks) };
            }
        }
        self.column_sums_portable(factors, column, stride, blocks)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn column_sums_avx2(
        &self,
        factors: &[usize],
        column: usize,
        stride: usize,
        blocks: usize,
    ) -> Vec<Option<f64>> {
        self.column_sums_portable(factors, column, stride, blocks)
    }

    #[inline(always)]
    fn column_sums_portable(
        &self,
        factors: &[usize],
        column: usize,
        stride: usize,
        blocks: usize,
    ) -> Vec<Option<f64>> {
        let mut out = Vec::with_capacity(blocks.div_ceil(stride) * factors.len());
        for b in (column..blocks).step_by(stride) {
            let k0 = b * BLOCK;
            for &j in factors {
                out.push(self.block_sum(j, k0, k0 + BLOCK));
            }
        }
        out
    }
}

/// Σ_i (x2[i] − 2·x1[i] + x0[i])² with `two` = 2: the bits of
/// `sum_of_squared_combinations([x2, x1, x0], [1.0, −2.0, 1.0])` (the same blocks
/// of 256, lanes of 8 and compensated block totals), whose terms
/// ((0 + x2) + (−2·x1)) + x0 differ from these only in the sign of a zero, which
/// squaring removes; without its leading 0 + and with −2·x1 on the multipliers
/// a term costs three additions instead of five.
#[inline(always)]
fn second_difference_squares([x2, x1, x0]: [&[f64]; 3], two: f64) -> f64 {
    let len = x0.len();
    debug_assert!(x1.len() == len && x2.len() == len);
    let mut total = Neumaier::new();
    let mut start = 0;
    while start < len {
        let end = (start + SUM_BLOCK).min(len);
        let (a, a_rest) = x2[start..end].as_chunks::<8>();
        let (b, b_rest) = x1[start..end].as_chunks::<8>();
        let (c, c_rest) = x0[start..end].as_chunks::<8>();
        let mut lanes = [0.0f64; 8];
        for ((a, b), c) in a.iter().zip(b).zip(c) {
            for l in 0..8 {
                let v = (a[l] - two * b[l]) + c[l];
                lanes[l] += v * v;
            }
        }
        for ((a, b), c) in a_rest.iter().zip(b_rest).zip(c_rest) {
            let v = (a - two * b) + c;
            lanes[0] += v * v;
        }
        total.add(lanes.iter().sum());
        start = end;
    }
    total.value()
}

/// Σ_i (x3[i] − 3·x2[i] + 3·x1[i] − x0[i])²: the bits of
/// `sum_of_squared_combinations([x3, x2, x1, x0], [1.0, −3.0, 3.0, −1.0])`
/// (x + (−3·y) = x − 3·y exactly; the leading 0 + changes only a zero's sign).
#[inline(always)]
fn third_difference_squares([x3, x2, x1, x0]: [&[f64]; 4]) -> f64 {
    let len = x0.len();
    debug_assert!(x1.len() == len && x2.len() == len && x3.len() == len);
    let mut total = Neumaier::new();
    let mut start = 0;
    while start < len {
        let end = (start + SUM_BLOCK).min(len);
        let (a, a_rest) = x3[start..end].as_chunks::<8>();
        let (b, b_rest) = x2[start..end].as_chunks::<8>();
        let (c, c_rest) = x1[start..end].as_chunks::<8>();
        let (d, d_rest) = x0[start..end].as_chunks::<8>();
        let mut lanes = [0.0f64; 8];
        for (((a, b), c), d) in a.iter().zip(b).zip(c).zip(d) {
            for l in 0..8 {
                let v = ((a[l] - 3.0 * b[l]) + 3.0 * c[l]) - d[l];
                lanes[l] += v * v;
            }
        }
        for (((a, b), c), d) in a_rest.iter().zip(b_rest).zip(c_rest).zip(d_rest) {
            let v = ((a - 3.0 * b) + 3.0 * c) - d;
            lanes[0] += v * v;
        }
        total.add(lanes.iter().sum());
        start = end;
    }
    total.value()
}

/// Terms per plainly summed block (`sum_of_squared_combinations`' block).
const SUM_BLOCK: usize = 256;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::Statistic;

    #[test]
    fn difference_kernels_give_the_bits_of_the_combinations() {
        use crate::allan::sum::sum_of_squared_combinations;
        // Magnitudes over many decades, exact zeros of either sign, lengths with
        // and without a remainder of the lanes and of the blocks.
        let x: Vec<f64> = crate::allan::test_signals::noise(5000, 0x9E37_79B9)
            .iter()
            .enumerate()
            .map(|(k, u)| match k % 97 {
                0 => 0.0,
                1 => -0.0,
                _ => u * 10f64.powi((k % 23) as i32 - 11),
            })
            .collect();
        for len in [0, 1, 7, 8, 9, 255, 256, 257, 1000, 2048, 4001] {
            for m in [1, 2, 5, 64, 250] {
                let w = |lag: usize| &x[lag..lag + len];
                let two = second_difference_squares([w(2 * m), w(m), w(0)], 2.0);
                let want = sum_of_squared_combinations([w(2 * m), w(m), w(0)], [1.0, -2.0, 1.0]);
                assert_eq!(two.to_bits(), want.to_bits(), "second, len {len} m {m}");
                let three = third_difference_squares([w(3 * m), w(2 * m), w(m), w(0)]);
                let want = sum_of_squared_combinations(
                    [w(3 * m), w(2 * m), w(m), w(0)],
                    [1.0, -3.0, 3.0, -1.0],
                );
                assert_eq!(three.to_bits(), want.to_bits(), "third, len {len} m {m}");
            }
        }
    }

    #[test]
    fn columns_give_the_bits_of_the_tasks() {
        let n = 7 * COLUMN + 12_345;
        let c: Vec<f64> = std::iter::once(0.0)
            .chain(
                crate::allan::test_signals::noise(n, 77)
                    .iter()
                    .scan(0.0, |acc, y| {
                        *acc += y;
                        Some(*acc)
                    }),
            )
            .collect();
        let ms = [1, 7, 4096, COLUMN, 2 * COLUMN, 3 * COLUMN, COLUMN + 1];
        crate::simd::at_every_level(|level| {
            for difference in [Difference::Second, Difference::Third] {
                let never = &crate::interrupt::NEVER;
                let fast = sums_of_squares(&c, &ms, difference, never);
                let tasks = sweep_sums(&c, &ms, difference, never, |_| false);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&fast), bits(&tasks), "{difference:?} at {level:?}");
                // Every factor has terms but 3·COLUMN in the third difference.
                assert!(fast[..5].iter().all(|&s| s > 0.0), "{fast:?}");
            }
        });
    }

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
