//! Estimates of a record with missing samples, run by run.
//!
//! The gap-free runs of samples ([`Gaps::segments`]) are analysed as records of
//! their own: the difference estimators' terms inside a run are exactly those of
//! the whole record that touch no missing sample, the noise type is identified on
//! the longest run, and the EDF pools the runs. Each run's estimate has
//! Greenhall's EDF ν_s for its length and carries the share w_s of the terms, so,
//! treating the runs as independent, 1/ν = Σ w_s²/ν_s.
//!
//! Cost. Runs of equal length share one EDF evaluation (they are counted by
//! length); the blocked sweep runs once per run, in parallel.

use std::collections::BTreeMap;
use std::ops::Range;

use rayon::prelude::*;

use super::fast::blocked::{self, Difference};
use super::phase::{Gaps, Phase};
use super::sum::column_totals;
use super::Statistic;
use crate::interrupt::Interrupt;

/// Phase points → how many runs have that many, over the runs where the
/// estimator has terms. Statistics that cannot skip gaps have no runs.
pub fn run_lengths(
    statistic: Statistic,
    c: &[f64],
    segments: &[Range<usize>],
    m: usize,
) -> BTreeMap<usize, usize> {
    let mut lengths = BTreeMap::new();
    let Some(estimator) = statistic.difference_variance() else {
        return lengths;
    };
    for s in segments {
        let len = estimator.segment_phase(c, s, m).len();
        if statistic.terms(len, m) > 0 {
            *lengths.entry(len).or_insert(0) += 1;
        }
    }
    lengths
}

/// Terms over the runs with `lengths` phase points.
pub fn terms_over_runs(lengths: &BTreeMap<usize, usize>, statistic: Statistic, m: usize) -> usize {
    lengths
        .iter()
        .map(|(&l, &n)| n * statistic.terms(l, m))
        .sum()
}

/// [`blocked::sums_of_squares`] over the gap-free runs of a record: the terms
/// inside one run are exactly those of the blocked sweep over its phase points.
pub fn sums_over_runs(
    c: &[f64],
    segments: &[Range<usize>],
    ms: &[usize],
    difference: Difference,
    stop: &Interrupt,
) -> Vec<f64> {
    let partials: Vec<Vec<f64>> = segments
        .par_iter()
        .map(|s| blocked::sums_of_squares(&c[s.start..=s.end], ms, difference, stop))
        .collect();
    column_totals(&partials, ms.len())
}

/// The phase the noise type is identified on: the whole record, or with gaps
/// its longest gap-free run (the lag-1 method needs an unbroken series).
pub fn identification_phase(phase: &Phase) -> &[f64] {
    match phase.gaps.as_ref().and_then(Gaps::longest) {
        None => &phase.c,
        Some(s) => &phase.c[s.start..=s.end],
    }
}

/// The EDF of an estimate pooled over runs with `lengths` phase points (see the
/// module notes): 1/ν = Σ_s (T_s/T)²/ν_s. NaN without terms.
pub fn pooled_edf(
    lengths: &BTreeMap<usize, usize>,
    terms: usize,
    statistic: Statistic,
    m: usize,
    edf_of: impl Fn(usize) -> f64,
) -> f64 {
    if terms == 0 {
        return f64::NAN;
    }
    let total = terms as f64;
    let inverse: f64 = lengths
        .iter()
        .map(|(&len, &count)| {
            let share = statistic.terms(len, m) as f64 / total;
            count as f64 * share * share / edf_of(len)
        })
        .sum();
    1.0 / inverse
}
