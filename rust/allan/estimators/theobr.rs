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
//! Cost. κ needs Theo1 at n + 1 ≈ N/30 averaging factors up to M ≈ 0.13·N:
//! factor by factor that is Σ_i (N − m_i)·m_i/2 ≈ N³/900 steps directly, or
//! ≈ N²/30·log²(m) with the kernel's O(N log² m) expansion. Instead, all of
//! them come from one exact sweep (`fast::theo1_sweep`): an O(N log N)
//! autocorrelation, then O(M²) integer pair products, ≈ 0.02·N² in all, and
//! the AVARs from the same autocorrelation in O(m) each. The sweep is checked
//! against the per-factor estimators at the first and the middle ratio; should
//! they differ by more than 1e-9 the ratios are computed factor by factor
//! (in parallel, one task per i) as before. The ratios are summed in order with
//! compensation, so κ does not depend on the thread count. [`estimated_seconds`]
//! turns the work into a time, for a warning before long runs.

use rayon::prelude::*;

use super::difference::oavar;
use super::theo1::{self, theo1_var, theo1_work};
use crate::allan::fast::exact_phase::ExactPhase;
use crate::allan::fast::theo1_sweep::theo1_sums;
use crate::allan::sum::Neumaier;
use crate::interrupt::Interrupt;

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

/// The ladder of averaging factors the bias ratio averages over.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Ladder {
    /// n = ⌊0.1·N/3⌋ − 3: ratios from 9τ0 to 10 % of the record (Taylor & Howe
    /// 2010, Stable32).
    #[default]
    TaylorHowe,
    /// n = ⌊N/6⌋ − 3 (SP 1065 eq. 33 as printed): ratios out to half the record,
    /// the sweep to ≈ 2N/3 instead of 0.13·N, so about 25 times the work. Its
    /// last AVAR would have no term when N is a multiple of 6; the ladder stops
    /// at the last AVAR with one.
    Sp1065,
}

impl Ladder {
    pub fn name(self) -> &'static str {
        match self {
            Ladder::TaylorHowe => "taylor-howe",
            Ladder::Sp1065 => "sp1065",
        }
    }

    /// n for N phase points (the ratio averages n + 1 terms), or `None` when N is
    /// too short.
    pub fn count(self, n_phase: usize) -> Option<usize> {
        match self {
            Ladder::TaylorHowe => ratio_count(n_phase),
            Ladder::Sp1065 => {
                let printed = (n_phase / 6).checked_sub(3)?;
                // AVAR(9 + 3i) needs N − 2(9 + 3i) ≥ 1.
                let with_terms = (n_phase.checked_sub(1)? / 2).checked_sub(9)? / 3;
                Some(printed.min(with_terms))
            }
        }
    }
}

impl std::str::FromStr for Ladder {
    type Err = crate::error::CoreError;
    fn from_str(name: &str) -> Result<Self, Self::Err> {
        [Ladder::TaylorHowe, Ladder::Sp1065]
            .into_iter()
            .find(|l| l.name() == name)
            .ok_or_else(|| {
                crate::error::CoreError::InvalidArgument(format!(
                    "ratio ladder must be 'taylor-howe' or 'sp1065'; got {name:?}"
                ))
            })
    }
}

/// How the bias ratio is computed: its ladder, and `block` > 1 for the
/// "fast ThêoBR", whose ratio comes from the phase at every block-th point
/// (the record averaged in blocks of that many samples): the sweep's work
/// shrinks by block², Theo1 at the requested factors stays that of the whole
/// record, and κ changes by the error docs/total.md tabulates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RatioOptions {
    pub ladder: Ladder,
    pub block: usize,
}

impl Default for RatioOptions {
    fn default() -> Self {
        RatioOptions {
            ladder: Ladder::TaylorHowe,
            block: 1,
        }
    }
}

impl RatioOptions {
    /// Phase points the ratio is computed on, of `n_phase`.
    pub fn ratio_points(&self, n_phase: usize) -> usize {
        (n_phase.saturating_sub(1)) / self.block.max(1) + 1
    }
}

/// Averaging factors (AVAR m, Theo1 m) of the i-th ratio.
pub fn ratio_factors(i: usize) -> (usize, usize) {
    (9 + 3 * i, 12 + 4 * i)
}

/// AVAR/Theo1 with the 0/0 of a linear phase (Theo1 vanishes only there, and
/// AVAR with it) counted as no bias (ratio 1).
fn ratio_of(avar: f64, theo: f64) -> f64 {
    if theo == 0.0 {
        1.0
    } else {
        avar / theo
    }
}

/// One ratio AVAR(9 + 3i)/Theo1(12 + 4i), each by its own estimator.
fn ratio(c: &[f64], i: usize, stop: &Interrupt) -> f64 {
    let (ma, mt) = ratio_factors(i);
    ratio_of(oavar(c, ma), theo1_var(c, mt, stop))
}

/// Largest relative difference allowed between the sweep and the per-factor
/// estimators at the factors checked.
const CHECK_TOLERANCE: f64 = 1e-9;

/// κ and Theo1 of one phase.
#[derive(Clone, Debug, PartialEq)]
pub struct BiasRatio {
    pub kappa: f64,
    /// (m, Theo1 variance) for the requested factors the sweep reached, by m.
    pub theo1: Vec<(usize, f64)>,
}

impl BiasRatio {
    /// Theo1 at m from the sweep, else by its own estimator.
    pub fn theo1_var(&self, c: &[f64], m: usize, stop: &Interrupt) -> f64 {
        match self.theo1.binary_search_by_key(&m, |&(k, _)| k) {
            Ok(i) => self.theo1[i].1,
            Err(_) => theo1_var(c, m, stop),
        }
    }
}

/// The n + 1 ratios of one phase and (m, Theo1) at the extra factors swept.
type Swept = (Vec<f64>, Vec<(usize, f64)>);

/// The n + 1 ratios of one phase from the exact all-factor sweep
/// (`fast::theo1_sweep`), with Theo1 at the factors of `extra` it passes on the
/// way; `None` if it could not run or disagrees with the per-factor estimators
/// at the first and the middle ratio.
fn swept_ratios(c: &[f64], n: usize, extra: &[usize], stop: &Interrupt) -> Option<Swept> {
    let n_phase = c.len();
    let (avar_ms, theo_ms): (Vec<usize>, Vec<usize>) = (0..=n).map(ratio_factors).unzip();
    let max_lag = 2 * avar_ms[n];
    let exact = ExactPhase::new(c, max_lag)?;
    let top = theo_ms[n];
    let mut swept_ms: Vec<usize> = theo_ms
        .iter()
        .chain(extra.iter().filter(|&&m| m % 2 == 0 && m >= 2 && m <= top))
        .copied()
        .collect();
    swept_ms.sort_unstable();
    swept_ms.dedup();
    // The sweep runs on one thread; the AVARs and the check's per-factor
    // estimators beside it.
    let checked = [0, n / 2];
    let (sums, (avar, direct)) = rayon::join(
        || theo1_sums(&exact, &swept_ms, stop),
        || {
            let avar: Vec<f64> = avar_ms
                .par_iter()
                .map(|&m| {
                    if stop.raised() {
                        return f64::NAN;
                    }
                    exact.allan_sum(m) / (2.0 * (m * m) as f64 * (n_phase - 2 * m) as f64)
                })
                .collect();
            let direct: Vec<(f64, f64)> = checked
                .par_iter()
                .map(|&i| {
                    let (ma, mt) = ratio_factors(i);
                    (theo1_var(c, mt, stop), oavar(c, ma))
                })
                .collect();
            (avar, direct)
        },
    );
    let sums = sums?;
    let theo_at: Vec<(usize, f64)> = swept_ms
        .iter()
        .zip(&sums)
        .map(|(&m, s)| (m, s / (0.75 * (n_phase - m) as f64 * (m * m) as f64)))
        .collect();
    let find = |m: usize| {
        theo_at[theo_at.binary_search_by_key(&m, |&(k, _)| k).ok()?]
            .1
            .into()
    };
    let theo: Vec<f64> = theo_ms.iter().map(|&m| find(m)).collect::<Option<_>>()?;
    let agrees = |got: f64, want: f64| (got - want).abs() <= CHECK_TOLERANCE * want.abs();
    for (&i, &(theo1_direct, avar_direct)) in checked.iter().zip(&direct) {
        if !agrees(theo[i], theo1_direct) || !agrees(avar[i], avar_direct) {
            return None;
        }
    }
    let extras = theo_at
        .into_iter()
        .filter(|(m, _)| extra.contains(m))
        .collect();
    Some((
        avar.iter()
            .zip(&theo)
            .map(|(&a, &t)| ratio_of(a, t))
            .collect(),
        extras,
    ))
}

/// The bias ratio κ of each phase (all of the same length) with Theo1 at the
/// factors of `ms` the sweep reached, or `None` when the phases are shorter
/// than [`MIN_PHASE_POINTS`]. Each phase's ratios come from the exact sweep,
/// or, if that fails its check, factor by factor. The values are meaningless
/// once `stop` is raised (the caller checks it).
pub fn bias_ratios(phases: &[&[f64]], ms: &[usize], stop: &Interrupt) -> Option<Vec<BiasRatio>> {
    bias_ratios_with(phases, ms, RatioOptions::default(), stop)
}

/// [`bias_ratios`] with a ladder and block (see [`RatioOptions`]); with a block
/// the sweep gives no Theo1 values (they belong to the whole record).
pub fn bias_ratios_with(
    phases: &[&[f64]],
    ms: &[usize],
    options: RatioOptions,
    stop: &Interrupt,
) -> Option<Vec<BiasRatio>> {
    let n_phase = phases.first()?.len();
    if phases.iter().any(|c| c.len() != n_phase) {
        return None;
    }
    let block = options.block.max(1);
    let decimated: Vec<Vec<f64>> = if block > 1 {
        phases
            .iter()
            .map(|c| c.iter().step_by(block).copied().collect())
            .collect()
    } else {
        Vec::new()
    };
    let phases: Vec<&[f64]> = if block > 1 {
        decimated.iter().map(|c| c.as_slice()).collect()
    } else {
        phases.to_vec()
    };
    let n = options.ladder.count(phases[0].len())?;
    let ms = if block > 1 { &[][..] } else { ms };
    let per_phase: Vec<Swept> = phases
        .par_iter()
        .map(|c| match swept_ratios(c, n, ms, stop) {
            Some(found) => found,
            None if stop.raised() => (vec![f64::NAN], Vec::new()),
            None => (
                (0..=n)
                    .into_par_iter()
                    .map(|i| {
                        if stop.raised() {
                            f64::NAN
                        } else {
                            ratio(c, i, stop)
                        }
                    })
                    .collect(),
                Vec::new(),
            ),
        })
        .collect();
    Some(
        per_phase
            .into_iter()
            .map(|(r, theo1)| BiasRatio {
                kappa: r.iter().sum::<Neumaier>().value() / r.len() as f64,
                theo1,
            })
            .collect(),
    )
}

/// The bias ratio κ of one phase (see [`bias_ratios`]).
pub fn bias_ratio(c: &[f64], stop: &Interrupt) -> Option<f64> {
    bias_ratios(&[c], &[], stop).map(|v| v[0].kappa)
}

/// Work of ThêoBR on one phase of `n_phase` points at `ms`, as (direct steps,
/// fast units) of Theo1 at `ms` (see [`theo1_work`]) and the sweep's pair
/// products for the bias ratio: M² + Σ_i m_i/2 (both ends' pair triangles, then
/// the terms of each ratio's factor), 0 when the ratio is not defined.
pub fn theobr_work(n_phase: usize, ms: &[usize]) -> (f64, f64, f64) {
    theobr_work_with(n_phase, ms, RatioOptions::default())
}

/// [`theobr_work`] with a ladder and block (the sweep runs on the ratio's points).
pub fn theobr_work_with(n_phase: usize, ms: &[usize], options: RatioOptions) -> (f64, f64, f64) {
    let ratio_points = options.ratio_points(n_phase);
    let sweep = options.ladder.count(ratio_points).map_or(0.0, |n| {
        let top = ratio_factors(n).1 as f64;
        let terms: f64 = (0..=n).map(|i| (ratio_factors(i).1 / 2) as f64).sum();
        top * top + terms
    });
    let (direct, fast) = ms
        .iter()
        .map(|&m| theo1_work(n_phase, m))
        .fold((0.0, 0.0), |(a, b), (c, d)| (a + c, b + d));
    (direct, fast, sweep)
}

/// Kernel rates, measured on the release build on the development machine
/// (2 shared cores; `benches/bench_theo.py` prints them next to real timings):
/// direct multiply-adds per second below `theo1::FFT_FROM`, N·log₂(m)² units
/// per second of the expansion above, and the sweep's pair products per second
/// (the IFMA path's; a CPU without it is several times slower).
/// They only decide whether a warning says a run will be long, so a machine
/// twice as fast or slow changes nothing else.
const DIRECT_STEPS_PER_SECOND: f64 = 1.2e9;
const FAST_UNITS_PER_SECOND: f64 = 1.1e9;
const SWEEP_PRODUCTS_PER_SECOND: f64 = 3.0e9;

/// Seconds ThêoBR at `ms` takes on one phase of `n_phase` points, from
/// [`theobr_work`] and the measured kernel rates.
pub fn estimated_seconds(n_phase: usize, ms: &[usize], options: RatioOptions) -> f64 {
    let (direct, fast, sweep) = theobr_work_with(n_phase, ms, options);
    direct / DIRECT_STEPS_PER_SECOND
        + fast / FAST_UNITS_PER_SECOND
        + sweep / SWEEP_PRODUCTS_PER_SECOND
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::phase::cumulative_phase;
    use crate::allan::test_signals::naive_theo1;
    use crate::interrupt::NEVER;

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
            let got = bias_ratio(&c, &NEVER).unwrap();
            assert!((got - want).abs() <= 1e-12 * want, "{got} vs {want}");
            // Random-walk FM: Theo1 underestimates AVAR, so κ > 1.
            assert!(got > 1.0, "{got}");
        }
    }

    #[test]
    fn the_sp1065_ladder_follows_its_printed_definition() {
        assert_eq!(Ladder::Sp1065.count(17), None);
        for n_phase in 90..2000 {
            let printed = n_phase / 6 - 3;
            let n = Ladder::Sp1065.count(n_phase).unwrap();
            // As printed, stopping only where the last AVAR would have no term.
            assert!(
                n == printed || n_phase - 2 * (9 + 3 * printed) < 1,
                "N = {n_phase}"
            );
            assert!(n_phase - 2 * (9 + 3 * n) >= 1, "N = {n_phase}");
        }
        let c = sample(400);
        let n = Ladder::Sp1065.count(c.len()).unwrap();
        assert_eq!(n, 63);
        let want: f64 = (0..=n)
            .map(|i| naive_oavar(&c, 9 + 3 * i) / naive_theo1(&c, 12 + 4 * i))
            .sum::<f64>()
            / (n + 1) as f64;
        let options = RatioOptions {
            ladder: Ladder::Sp1065,
            block: 1,
        };
        let got = bias_ratios_with(&[&c], &[], options, &NEVER).unwrap()[0].kappa;
        assert!((got - want).abs() <= 1e-12 * want, "{got} vs {want}");
        assert_eq!("sp1065".parse::<Ladder>().unwrap(), Ladder::Sp1065);
        assert!("stable32".parse::<Ladder>().is_err());
    }

    #[test]
    fn a_block_takes_the_ratio_from_every_block_th_phase_point() {
        let c = sample(1000);
        let options = RatioOptions {
            ladder: Ladder::TaylorHowe,
            block: 4,
        };
        let got = bias_ratios_with(&[&c], &[100], options, &NEVER).unwrap();
        let decimated: Vec<f64> = c.iter().step_by(4).copied().collect();
        assert_eq!(decimated.len(), options.ratio_points(c.len()));
        assert_eq!(got[0].kappa, bias_ratio(&decimated, &NEVER).unwrap());
        // Theo1 of the whole record is not taken from the decimated sweep.
        assert!(got[0].theo1.is_empty());
        assert_ne!(got[0].kappa, bias_ratio(&c, &NEVER).unwrap());
    }

    #[test]
    fn too_short_and_degenerate_phases() {
        assert_eq!(bias_ratio(&sample(88), &NEVER), None);
        assert_eq!(bias_ratio(&[], &NEVER), None);
        let flat = vec![0.0; 200];
        assert_eq!(bias_ratio(&flat, &NEVER), Some(1.0));
        let a = sample(200);
        let b = sample(201);
        assert_eq!(bias_ratios(&[&a, &b], &[], &NEVER), None);
    }

    #[test]
    fn several_phases_give_their_own_ratios() {
        let a = sample(300);
        let b: Vec<f64> = (0..301).map(|k| ((k * 37) % 17) as f64).collect();
        let both = bias_ratios(&[&a, &b], &[], &NEVER).unwrap();
        let kappas: Vec<f64> = both.iter().map(|r| r.kappa).collect();
        let alone = [&a, &b].map(|c| bias_ratio(c, &NEVER).unwrap());
        assert_eq!(kappas, alone);
    }

    #[test]
    fn the_sweep_passes_its_check_and_gives_theo1_on_the_way() {
        // The four noise types; the sweep's values are the definition's.
        for order in 0..4 {
            let mut c = crate::allan::test_signals::integrated_noise(1501, 11, order);
            if order == 0 {
                c = c.windows(2).map(|w| w[1] - w[0]).collect(); // white PM
            }
            let n = ratio_count(c.len()).unwrap();
            let (ratios, theo1) = swept_ratios(&c, n, &[10, 100, 198, 600], &NEVER).unwrap();
            assert_eq!(ratios.len(), n + 1);
            let ms: Vec<usize> = theo1.iter().map(|t| t.0).collect();
            assert_eq!(ms, vec![10, 100, 198]);
            for (m, var) in theo1 {
                let want = naive_theo1(&c, m);
                assert!((var - want).abs() <= 1e-10 * want, "m {m}: {var} vs {want}");
            }
        }
    }

    #[test]
    fn work_counts_the_theo1_regimes_and_the_sweep() {
        assert_eq!(theobr_work(50, &[]), (0.0, 0.0, 0.0));
        // N = 90: one ratio at m = 12: a 12² triangle and 6 terms; Theo1 at m = 20
        // directly: (90 − 20)·10 steps.
        assert_eq!(theobr_work(90, &[]), (0.0, 0.0, 144.0 + 6.0));
        assert_eq!(theobr_work(90, &[20]), (70.0 * 10.0, 0.0, 150.0));
        // N = 10001: 1024 adds N·log2(1024)² fast units.
        let (_, fast, sweep) = theobr_work(10_001, &[1024]);
        assert_eq!(fast, 10_001.0 * 100.0);
        assert_eq!(
            sweep,
            1332.0 * 1332.0 + (6..=666).step_by(2).sum::<usize>() as f64
        );
        assert_eq!(theo1_work(100, 100), (0.0, 0.0));
        let seconds = estimated_seconds(10_001, &[1024], RatioOptions::default());
        assert_eq!(
            seconds,
            fast / FAST_UNITS_PER_SECOND + sweep / SWEEP_PRODUCTS_PER_SECOND
        );
    }
}
