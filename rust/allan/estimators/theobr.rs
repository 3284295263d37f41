//! ThêoBR: Theo1 with its bias relative to the Allan variance removed by the
//! data's own AVAR/Theo1 ratio (Howe & Tasset 2004; Howe, "ThêoH: a hybrid,
//! high-confidence statistic that improves on the Allan deviation", Metrologia
//! 43, 2006; NIST SP 1065 §5.2.15):
//!
//! ThêoBR(m) = κ · Theo1(m),  κ = 1/(n+1) Σ_{i=0}^{n} AVAR(9 + 3i) / Theo1(12 + 4i),
//!
//! with n = ⌊0.1·N/3⌋ − 3 over the N phase points (so N ≥ 90) and AVAR the
//! overlapping Allan variance. Theo1 at m = 12 + 4i belongs to the same τ as AVAR
//! at 9 + 3i (τ = 0.75·m·τ0), so each ratio measures Theo1's bias at one τ
//! between 9τ0 and 10 % of the record; κ is their mean.
//!
//! Cost. κ needs Theo1 at n + 1 ≈ N/30 averaging factors up to ≈ 0.13·N: with
//! the direct sum that is Σ_i (N − m_i)·m_i/2 ≈ N³/900 steps; with the kernel's
//! O(N log² m) expansion from m = `theo1::FFT_FROM` (256) on it is
//! ≈ N²/30·log²(m), the dominant cost of ThêoBR for long records all the same. The ratios are independent, so they
//! are computed in parallel (one task per i, each kernel parallel inside) and
//! summed in order with compensation, so κ does not depend on the thread count.
//! [`estimated_seconds`] turns that work into a time, for a warning before long runs.

use rayon::prelude::*;

use super::difference::oavar;
use super::theo1::{self, theo1_var, theo1_work};
use crate::allan::sum::Neumaier;

/// Fewest phase points for which the bias ratio is defined (n ≥ 0).
pub const MIN_PHASE_POINTS: usize = 90;

/// Fewest samples ThêoBR accepts: N = samples + 1 phase points.
pub const MIN_SAMPLES: usize = MIN_PHASE_POINTS - 1;

/// Smallest averaging factor of ThêoBR: SP 1065's range is 10 ≤ m ≤ N − 1.
const MIN_FACTOR: usize = 10;

/// Terms of ThêoBR: Theo1's, over SP 1065's range 10 ≤ m ≤ N − 1, where the bias
/// ratio exists.
pub fn terms(n_phase: usize, m: usize) -> usize {
    if m >= MIN_FACTOR && ratio_count(n_phase).is_some() {
        theo1::terms(n_phase, m)
    } else {
        0
    }
}

/// n = ⌊0.1·N/3⌋ − 3 for N phase points (the ratio averages n + 1 terms), or
/// `None` when N is too short (n < 0).
pub fn ratio_count(n_phase: usize) -> Option<usize> {
    // ⌊0.1·N/3⌋ = ⌊N/30⌋ in exact integer arithmetic.
    (n_phase / 30).checked_sub(3)
}

/// Averaging factors (AVAR m, Theo1 m) of the i-th ratio.
pub fn ratio_factors(i: usize) -> (usize, usize) {
    (9 + 3 * i, 12 + 4 * i)
}

/// One ratio AVAR(9 + 3i)/Theo1(12 + 4i). Theo1 vanishes only for a linear
/// phase, where AVAR vanishes too; that 0/0 counts as no bias (ratio 1).
fn ratio(c: &[f64], i: usize) -> f64 {
    let (ma, mt) = ratio_factors(i);
    let avar = oavar(c, ma);
    let theo = theo1_var(c, mt);
    if theo == 0.0 {
        1.0
    } else {
        avar / theo
    }
}

/// The bias ratio κ of each phase (all of the same length), or `None` when the
/// phases are shorter than [`MIN_PHASE_POINTS`]. Work is spread over
/// (phase, i) pairs.
pub fn bias_ratios(phases: &[&[f64]]) -> Option<Vec<f64>> {
    let n_phase = phases.first()?.len();
    let n = ratio_count(n_phase)?;
    if phases.iter().any(|c| c.len() != n_phase) {
        return None;
    }
    let terms = n + 1;
    let ratios: Vec<f64> = (0..phases.len() * terms)
        .into_par_iter()
        .map(|k| ratio(phases[k / terms], k % terms))
        .collect();
    Some(
        ratios
            .chunks(terms)
            .map(|chunk| chunk.iter().sum::<Neumaier>().value() / terms as f64)
            .collect(),
    )
}

/// The bias ratio κ of one phase (see [`bias_ratios`]).
pub fn bias_ratio(c: &[f64]) -> Option<f64> {
    bias_ratios(&[c]).map(|v| v[0])
}

/// Work of the bias ratio of one phase of `n_phase` points plus Theo1 at `ms`,
/// as (direct steps, fast units) (see [`theo1_work`]); the ratio's part is 0
/// when it is not defined.
pub fn theobr_work(n_phase: usize, ms: &[usize]) -> (f64, f64) {
    let ratio_ms = ratio_count(n_phase)
        .map(|n| (0..=n).map(|i| ratio_factors(i).1).collect::<Vec<_>>())
        .unwrap_or_default();
    ratio_ms
        .iter()
        .chain(ms)
        .map(|&m| theo1_work(n_phase, m))
        .fold((0.0, 0.0), |(a, b), (c, d)| (a + c, b + d))
}

/// Theo1 kernel rates, measured on the release build on the development machine
/// (2 shared cores; `benches/bench_theo.py` prints them next to real timings):
/// direct multiply-adds per second below `theo1::FFT_FROM`, and N·log₂(m)² units
/// per second of the expansion above. They only decide whether a warning says a
/// run will be long, so a machine twice as fast or slow changes nothing else.
const DIRECT_STEPS_PER_SECOND: f64 = 1.2e9;
const FAST_UNITS_PER_SECOND: f64 = 1.1e9;

/// Seconds ThêoBR at `ms` takes on one phase of `n_phase` points, from
/// [`theobr_work`] and the measured kernel rates.
pub fn estimated_seconds(n_phase: usize, ms: &[usize]) -> f64 {
    let (direct, fast) = theobr_work(n_phase, ms);
    direct / DIRECT_STEPS_PER_SECOND + fast / FAST_UNITS_PER_SECOND
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::phase::cumulative_phase;
    use crate::allan::test_signals::naive_theo1;

    /// Direct transcriptions of the definitions on phase values.
    fn naive_oavar(x: &[f64], m: usize) -> f64 {
        let n = x.len();
        let s: f64 = (0..n - 2 * m)
            .map(|i| (x[i + 2 * m] - 2.0 * x[i + m] + x[i]).powi(2))
            .sum();
        s / (2.0 * (m * m) as f64 * (n - 2 * m) as f64)
    }

    fn sample(n: usize) -> Vec<f64> {
        // A random walk of a fixed pseudo-random sequence: Theo1 is biased there.
        let mut level = 0.0;
        let y: Vec<f64> = (0..n)
            .map(|k| {
                level += ((k * 7919 + 13) % 101) as f64 - 50.0;
                level
            })
            .collect();
        cumulative_phase(y.into_iter()).unwrap()
    }

    #[test]
    fn the_shortest_record_has_one_ratio() {
        assert_eq!(ratio_count(MIN_SAMPLES + 1), Some(0));
        assert_eq!(ratio_count(MIN_SAMPLES), None);
        assert!(terms(MIN_SAMPLES + 1, 10) > 0);
        assert_eq!(terms(MIN_SAMPLES, 10), 0);
    }

    #[test]
    fn ratio_count_follows_the_definition() {
        assert_eq!(ratio_count(89), None);
        assert_eq!(ratio_count(90), Some(0));
        assert_eq!(ratio_count(1001), Some(30));
        for n_phase in 90..2000 {
            let n = (0.1 * n_phase as f64 / 3.0 - 3.0).floor() as usize;
            assert_eq!(ratio_count(n_phase), Some(n), "N = {n_phase}");
        }
    }

    #[test]
    fn bias_ratio_matches_the_definition() {
        for n_samples in [89, 150, 400] {
            let c = sample(n_samples);
            let n = (0.1 * c.len() as f64 / 3.0 - 3.0).floor() as usize;
            let want: f64 = (0..=n)
                .map(|i| naive_oavar(&c, 9 + 3 * i) / naive_theo1(&c, 12 + 4 * i))
                .sum::<f64>()
                / (n + 1) as f64;
            let got = bias_ratio(&c).unwrap();
            assert!((got - want).abs() <= 1e-12 * want, "{got} vs {want}");
            // Random-walk FM: Theo1 underestimates AVAR, so κ > 1.
            assert!(got > 1.0, "{got}");
        }
    }

    #[test]
    fn too_short_and_degenerate_phases() {
        assert_eq!(bias_ratio(&sample(88)), None);
        assert_eq!(bias_ratio(&[]), None);
        let flat = vec![0.0; 200];
        assert_eq!(bias_ratio(&flat), Some(1.0));
        let a = sample(200);
        let b = sample(201);
        assert_eq!(bias_ratios(&[&a, &b]), None);
    }

    #[test]
    fn several_phases_give_their_own_ratios() {
        let a = sample(300);
        let b: Vec<f64> = (0..301).map(|k| ((k * 37) % 17) as f64).collect();
        let both = bias_ratios(&[&a, &b]).unwrap();
        assert_eq!(both, vec![bias_ratio(&a).unwrap(), bias_ratio(&b).unwrap()]);
    }

    #[test]
    fn work_counts_the_theo1_regimes() {
        assert_eq!(theobr_work(50, &[]), (0.0, 0.0));
        // N = 90: one ratio, Theo1 at m = 12: (90 − 12)·6 direct steps.
        assert_eq!(theobr_work(90, &[]), (78.0 * 6.0, 0.0));
        assert_eq!(theobr_work(90, &[20]), (78.0 * 6.0 + 70.0 * 10.0, 0.0));
        // N = 10001: ratios at m = 12, 16, …, 1332; 1024 adds N·log2(1024)² fast units.
        let (direct, fast) = theobr_work(10_001, &[]);
        let want: f64 = (12..256)
            .step_by(4)
            .map(|m| (10_001 - m) as f64 * (m / 2) as f64)
            .sum();
        assert_eq!(direct, want);
        let (_, with_tau) = theobr_work(10_001, &[1024]);
        assert!((with_tau - fast - 10_001.0 * 100.0).abs() < 1e-6 * fast);
        assert_eq!(theo1_work(100, 100), (0.0, 0.0));
        let seconds = estimated_seconds(10_001, &[1024]);
        assert_eq!(
            seconds,
            direct / DIRECT_STEPS_PER_SECOND + with_tau / FAST_UNITS_PER_SECOND
        );
    }
}
