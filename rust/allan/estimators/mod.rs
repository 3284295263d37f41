//! The estimators, one file per statistic family, each over the cumulative phase
//! of one channel; none knows the [`crate::allan::Statistic`] table above it.
//!
//! - `difference`: Allan, modified Allan, Hadamard (overlapping or not) and TOTVAR;
//! - `mtot_htot`: modified total and Hadamard total variances;
//! - `theo1`: Theo1, direct below its FFT threshold;
//! - `theobr`: ThêoBR's bias ratio and its cost.

pub mod difference;
pub mod mtot_htot;
pub mod theo1;
pub mod theobr;

use rayon::prelude::*;

use crate::allan::sum::Neumaier;
use crate::interrupt::Interrupt;

/// A variance estimate and the number of terms it averages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    pub var: f64,
    pub terms: usize,
}

impl Estimate {
    /// No term: the tau does not fit.
    pub const EMPTY: Estimate = Estimate {
        var: f64::NAN,
        terms: 0,
    };
}

/// Subsequences per parallel work item: large enough to amortise the scratch
/// buffer, small enough to balance two to sixteen threads.
const CHUNK_WORK: usize = 1 << 18;

/// Sum over `count` subsequences of `inner(i, zp, p)`, in parallel chunks with
/// per-chunk scratch buffers; chunk results are combined in order with
/// compensation so the answer does not depend on the thread count. Chunks
/// started after `stop` is raised are skipped (the sum is then meaningless).
fn sum_over_subsequences<F>(
    count: usize,
    m: usize,
    per_item: usize,
    inner: F,
    stop: &Interrupt,
) -> f64
where
    F: Fn(usize, &mut [f64], &mut [f64]) -> f64 + Sync,
{
    let chunk = (CHUNK_WORK / per_item.max(1)).clamp(1, count.max(1));
    let chunks = count.div_ceil(chunk);
    let parts: Vec<f64> = (0..chunks)
        .into_par_iter()
        .map(|k| {
            if stop.raised() {
                return 0.0;
            }
            let mut zp = vec![0.0; 3 * m + 1];
            let mut p = vec![0.0; 9 * m + 1];
            (k * chunk..((k + 1) * chunk).min(count))
                .map(|i| inner(i, &mut zp, &mut p))
                .sum::<Neumaier>()
                .value()
        })
        .collect();
    parts.into_iter().sum::<Neumaier>().value()
}
