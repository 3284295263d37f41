//! The Allan family over cumulative sums: estimates, noise identification and
//! equivalent degrees of freedom for many channels and taus at once.
//!
//! This file only orchestrates: [`Statistic`] (`statistic.rs`) says what each
//! statistic is, `estimators/` compute one tau of one channel, `fast/` holds the
//! kernels that make them O(n) or sweep all taus at once, `uncertainty/` the noise
//! identification and EDF, `runs.rs` the handling of missing samples, and
//! `phase.rs`/`running_sum.rs`/`sum.rs` the numerics they share. Dependencies
//! point down that list.
//!
//! Missing samples (NaN) are gaps. The difference estimators (Allan, modified
//! Allan, Hadamard; [`Statistic::skips_gaps`]) leave out every term whose window
//! touches a missing sample and count only the terms used; the total family
//! refuses gapped records. With gaps, the noise type is identified on the longest
//! gap-free run and the EDF pools the runs (see `runs.rs`; ν of the whole record
//! when there is no gap). A record without NaN takes exactly the gap-free code path.

pub mod estimators;
pub mod fast;
pub mod phase;
pub mod running_sum;
pub mod runs;
pub mod statistic;
pub mod sum;
#[cfg(test)]
mod test_signals;
pub mod uncertainty;

use std::collections::BTreeMap;

use rayon::prelude::*;

use crate::error::{CoreError, CoreResult};
use crate::interrupt::{Interrupt, NEVER};
pub use estimators::theobr::{Ladder, RatioOptions};
pub use estimators::Estimate;
pub use phase::{column_phases, contiguous_phase, row_major_phases, Gaps, Phase};
pub use statistic::Statistic;
use uncertainty::edf::EdfModel;
use uncertainty::{corner, noise_id};

/// Results for `taus.len()` taus × `channels` channels, tau-major
/// (`var[t * channels + c]`), the layout of a C-ordered `(taus, channels)` array.
#[derive(Clone, Debug, PartialEq)]
pub struct Analysis {
    pub channels: usize,
    /// NaN where a channel's gaps leave no term at that tau.
    pub var: Vec<f64>,
    /// Terms used per tau and channel (the same for every channel without gaps).
    pub terms: Vec<usize>,
    /// Noise type α used for the EDF at each tau and channel.
    pub alpha: Vec<i32>,
    /// Whether α was identified at that tau (false: taken from the nearest tau
    /// where it was, or white FM, α = 0, when no tau could be identified).
    pub alpha_identified: Vec<bool>,
    pub edf: Vec<f64>,
    /// Missing samples per channel.
    pub missing: Vec<usize>,
}

/// Estimates the statistic at every averaging factor in `ms` for every phase,
/// identifies the noise type and computes the EDF. Work is spread over
/// (channel, tau) pairs.
pub fn analyse(phases: &[Phase], statistic: Statistic, ms: &[usize]) -> CoreResult<Analysis> {
    let plan: Vec<(Statistic, usize)> = ms.iter().map(|&m| (statistic, m)).collect();
    analyse_plan(phases, &plan, &NEVER)
}

/// [`analyse`] with a statistic per tau: `plan[t]` = (statistic, m). ThêoH is
/// the plan of overlapping AVAR at its short taus and ThêoBR at its long ones.
/// Noise types missing at some taus are filled from the nearest identified taus
/// of the whole plan, so order the plan by τ. Raising `stop` ends the work
/// early with [`CoreError::Interrupted`].
pub fn analyse_plan(
    phases: &[Phase],
    plan: &[(Statistic, usize)],
    stop: &Interrupt,
) -> CoreResult<Analysis> {
    analyse_plan_with(phases, plan, RatioOptions::default(), stop)
}

/// [`analyse_plan`] with ThêoBR's bias ratio computed as `ratio` says (its
/// ladder, or the fast ThêoBR's block).
pub fn analyse_plan_with(
    phases: &[Phase],
    plan: &[(Statistic, usize)],
    ratio: RatioOptions,
    stop: &Interrupt,
) -> CoreResult<Analysis> {
    let n_phase = check_phases(phases, plan)?;
    if ratio.block == 0 {
        return Err(CoreError::InvalidArgument(
            "the bias ratio's block must be at least 1; got 0".into(),
        ));
    }
    let mut job = Job::new(phases, plan, n_phase)?;
    job.ratio = ratio;
    // The noise types need only the phase: identified beside the sweep.
    let (swept, alphas) = rayon::join(|| job.sweep_blocked(stop), || job.identify(stop));
    stop.check()?;
    let estimates = job.estimate_pairs(&swept, &alphas, stop);
    stop.check()?;
    let (var, mut alpha, alpha_identified) = job.gather(estimates)?;
    for c in 0..job.channels {
        noise_id::fill_from_nearest(&mut alpha, &alpha_identified, c, job.channels, plan.len());
    }
    let edf = job.edf(&alpha);
    Ok(Analysis {
        channels: job.channels,
        var,
        terms: job.terms,
        alpha,
        alpha_identified,
        edf,
        missing: phases
            .iter()
            .map(|p| p.gaps.as_ref().map_or(0, |g| g.missing))
            .collect(),
    })
}

/// The common length of the phases in phase points, after checking that there is
/// a channel, that all have that length, and that gaps meet only statistics that
/// can skip them.
fn check_phases(phases: &[Phase], plan: &[(Statistic, usize)]) -> CoreResult<usize> {
    let Some(first) = phases.first() else {
        return Err(CoreError::InvalidArgument(
            "x must have at least one channel".into(),
        ));
    };
    let n_phase = first.c.len();
    if phases.iter().any(|p| p.c.len() != n_phase) {
        return Err(CoreError::InvalidArgument(
            "all channels must have the same length".into(),
        ));
    }
    if let Some((c, gaps)) = phases
        .iter()
        .enumerate()
        .find_map(|(c, p)| p.gaps.as_ref().map(|g| (c, g)))
    {
        if let Some(&(s, _)) = plan.iter().find(|(s, _)| !s.skips_gaps()) {
            return Err(CoreError::InvalidArgument(format!(
                "x has {} missing samples (NaN) in channel {c}; {s:?} cannot skip gaps",
                gaps.missing
            )));
        }
    }
    Ok(n_phase)
}

/// One analysis: the (tau, channel) pairs of a plan and their term counts.
struct Job<'a> {
    phases: &'a [Phase],
    plan: &'a [(Statistic, usize)],
    n_phase: usize,
    channels: usize,
    /// (tau index, channel), tau-major.
    pairs: Vec<(usize, usize)>,
    /// With gaps: how many runs have each length (in phase points) that holds a term.
    runs: Vec<Option<BTreeMap<usize, usize>>>,
    /// Terms per pair.
    terms: Vec<usize>,
    /// How ThêoBR's bias ratio is computed.
    ratio: RatioOptions,
}

impl<'a> Job<'a> {
    fn new(
        phases: &'a [Phase],
        plan: &'a [(Statistic, usize)],
        n_phase: usize,
    ) -> CoreResult<Self> {
        let full_terms: Vec<usize> = plan.iter().map(|&(s, m)| s.terms(n_phase, m)).collect();
        if let Some(pos) = full_terms.iter().position(|&t| t == 0) {
            return Err(CoreError::InvalidArgument(format!(
                "tau of {} samples does not fit in {} samples for this statistic",
                plan[pos].1,
                n_phase.saturating_sub(1)
            )));
        }
        let channels = phases.len();
        let pairs: Vec<(usize, usize)> = (0..plan.len())
            .flat_map(|t| (0..channels).map(move |c| (t, c)))
            .collect();
        let runs: Vec<Option<BTreeMap<usize, usize>>> = pairs
            .iter()
            .map(|&(t, c)| {
                let (s, m) = plan[t];
                let g = phases[c].gaps.as_ref()?;
                Some(runs::run_lengths(s, &phases[c].c, &g.segments, m))
            })
            .collect();
        let terms = pairs
            .iter()
            .zip(&runs)
            .map(|(&(t, _), lengths)| match lengths {
                None => full_terms[t],
                Some(lengths) => runs::terms_over_runs(lengths, plan[t].0, plan[t].1),
            })
            .collect();
        Ok(Job {
            phases,
            plan,
            n_phase,
            channels,
            pairs,
            runs,
            terms,
            ratio: RatioOptions::default(),
        })
    }

    /// Each statistic of the plan once, in order of first appearance, with its
    /// tau indices and averaging factors.
    fn by_statistic(&self) -> Vec<(Statistic, Vec<usize>, Vec<usize>)> {
        let mut statistics: Vec<Statistic> = Vec::new();
        for &(s, _) in self.plan {
            if !statistics.contains(&s) {
                statistics.push(s);
            }
        }
        statistics
            .into_iter()
            .map(|s| {
                let taus: Vec<usize> = (0..self.plan.len())
                    .filter(|&t| self.plan[t].0 == s)
                    .collect();
                let ms = taus.iter().map(|&t| self.plan[t].1).collect();
                (s, taus, ms)
            })
            .collect()
    }

    /// The overlapping Allan and Hadamard variances sweep all their taus of a
    /// channel at once (see `fast::blocked`, run over each gap-free run); every
    /// other pair is `None` here and goes tau by tau.
    /// Meaningless once `stop` is raised.
    fn sweep_blocked(&self, stop: &Interrupt) -> Vec<Option<f64>> {
        let mut swept: Vec<Option<f64>> = vec![None; self.pairs.len()];
        for (statistic, taus, ms) in self.by_statistic() {
            let (Some(difference), Some(estimator)) =
                (statistic.spec().blocked, statistic.difference_variance())
            else {
                continue;
            };
            let sums: Vec<Vec<f64>> = self
                .phases
                .par_iter()
                .map(|p| match &p.gaps {
                    None => fast::blocked::sums_of_squares(&p.c, &ms, difference, stop),
                    Some(g) => runs::sums_over_runs(&p.c, &g.segments, &ms, difference, stop),
                })
                .collect();
            for (k, &t) in taus.iter().enumerate() {
                for (c, channel_sums) in sums.iter().enumerate() {
                    let i = t * self.channels + c;
                    swept[i] = Some(estimator.variance_from_sum(
                        channel_sums[k],
                        self.plan[t].1,
                        self.terms[i],
                    ));
                }
            }
        }
        swept
    }

    /// The noise type of every pair, if its series is long enough: each channel's
    /// factors of one statistic together (`noise_id::identify_alphas`).
    /// Meaningless once `stop` is raised.
    fn identify(&self, stop: &Interrupt) -> Vec<Option<i32>> {
        let groups: Vec<(Statistic, Vec<usize>, Vec<usize>, usize)> = self
            .by_statistic()
            .into_iter()
            .flat_map(|(s, taus, ms)| {
                let factors: Vec<usize> = ms.iter().map(|&m| s.noise_id_factor(m)).collect();
                (0..self.channels).map(move |c| (s, taus.clone(), factors.clone(), c))
            })
            .collect();
        let found: Vec<Vec<Option<i32>>> = groups
            .par_iter()
            .map(|(s, _, factors, c)| {
                if stop.raised() {
                    return vec![None; factors.len()];
                }
                let phase = runs::identification_phase(&self.phases[*c]);
                noise_id::identify_alphas(phase, factors, s.spec().dmax)
            })
            .collect();
        let mut alphas = vec![None; self.pairs.len()];
        for ((_, taus, _, c), found) in groups.iter().zip(found) {
            for (&t, alpha) in taus.iter().zip(found) {
                alphas[t * self.channels + c] = alpha;
            }
        }
        alphas
    }

    /// The variance of every pair (from the sweep where it ran) beside its noise
    /// type from `alphas`. Pairs not started before `stop` is raised are NaN.
    fn estimate_pairs(
        &self,
        swept: &[Option<f64>],
        alphas: &[Option<i32>],
        stop: &Interrupt,
    ) -> Vec<(f64, Option<i32>)> {
        // ThêoBR's bias ratio belongs to a channel, not a tau: computed once each.
        // The sweep behind it also gives Theo1 at ThêoBR's factors up to ≈ 0.13·N.
        let theobr_ms: Vec<usize> = self
            .plan
            .iter()
            .filter(|(s, _)| *s == Statistic::TheoBR)
            .map(|&(_, m)| m)
            .collect();
        let ratios = if theobr_ms.is_empty() {
            None
        } else {
            let refs: Vec<&[f64]> = self.phases.iter().map(|p| p.c.as_slice()).collect();
            estimators::theobr::bias_ratios_with(&refs, &theobr_ms, self.ratio, stop)
        };
        self.pairs
            .par_iter()
            .enumerate()
            .map(|(i, &(t, c))| {
                if stop.raised() {
                    return (f64::NAN, None);
                }
                let (statistic, m) = self.plan[t];
                let phase = &self.phases[c];
                let var = match (swept[i], statistic, &ratios, &phase.gaps) {
                    (Some(v), _, _, _) => v,
                    (None, Statistic::TheoBR, Some(r), _) => {
                        r[c].kappa * r[c].theo1_var(&phase.c, m, stop)
                    }
                    (None, _, _, None) => statistic.estimate(&phase.c, m, stop).var,
                    (None, _, _, Some(g)) => statistic
                        .estimate_in_segments(&phase.c, &g.segments, m)
                        .map_or(f64::NAN, |e| e.var),
                };
                (var, alphas[i])
            })
            .collect()
    }

    /// Variances and noise types as arrays; a variance that overflowed where there
    /// are terms is an error.
    fn gather(
        &self,
        estimates: Vec<(f64, Option<i32>)>,
    ) -> CoreResult<(Vec<f64>, Vec<i32>, Vec<bool>)> {
        let mut var = Vec::with_capacity(self.pairs.len());
        let mut alpha = vec![0; self.pairs.len()];
        let mut alpha_identified = vec![false; self.pairs.len()];
        for (i, (v, a)) in estimates.into_iter().enumerate() {
            if !v.is_finite() && self.terms[i] > 0 {
                let (t, c) = self.pairs[i];
                return Err(CoreError::Numerical(format!(
                    "x is too large in magnitude: the variance at m = {} overflows double \
                     precision (channel {c}); rescale x",
                    self.plan[t].1
                )));
            }
            var.push(v);
            if let Some(a) = a {
                alpha[i] = a;
                alpha_identified[i] = true;
            }
        }
        Ok((var, alpha, alpha_identified))
    }

    /// The EDF of every pair for its noise type, pooled over the runs with gaps,
    /// with the phase points counted a corner apart where a channel's phase noise
    /// begins beyond its first tau (`uncertainty::corner`).
    fn edf(&self, alpha: &[i32]) -> Vec<f64> {
        let corners = self.phase_noise_corners(alpha);
        self.pairs
            .iter()
            .enumerate()
            .map(|(i, &(t, _))| {
                let (statistic, m) = self.plan[t];
                let corner = corners[i];
                match (statistic.spec().edf, &self.runs[i]) {
                    (EdfModel::Greenhall(est), Some(lengths)) => {
                        runs::pooled_edf(lengths, self.terms[i], statistic, m, |len| {
                            corner::edf_beyond_corner(
                                |m, n| uncertainty::edf::greenhall_edf(alpha[i], est, m, n),
                                m,
                                len,
                                corner,
                            )
                        })
                    }
                    (model, _) => corner::edf_beyond_corner(
                        |m, n| model.edf(alpha[i], m, n),
                        m,
                        self.n_phase,
                        corner,
                    ),
                }
            })
            .collect()
    }

    /// The corner of every pair: its channel's and statistic's series in turn.
    fn phase_noise_corners(&self, alpha: &[i32]) -> Vec<usize> {
        let mut corners = vec![1; self.pairs.len()];
        for (_, taus, ms) in self.by_statistic() {
            for c in 0..self.channels {
                let series: Vec<i32> = taus.iter().map(|&t| alpha[t * self.channels + c]).collect();
                for (k, corner) in corner::phase_noise_corners(&ms, &series)
                    .into_iter()
                    .enumerate()
                {
                    corners[taus[k] * self.channels + c] = corner;
                }
            }
        }
        corners
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn analysis_shapes_and_fallback() {
        let y: Vec<f64> = (0..200).map(|k| ((k * 37) % 17) as f64).collect();
        let phases = column_phases(vec![y.iter().copied(), y.iter().copied()]).unwrap();
        let a = analyse(
            &phases,
            Statistic::Allan { overlapping: true },
            &[1, 2, 16, 64],
        )
        .unwrap();
        assert_eq!(a.var.len(), 8);
        assert_eq!(a.terms, vec![199, 199, 197, 197, 169, 169, 73, 73]);
        // m = 16 leaves 13 decimated points: not identified, taken from the
        // identified taus (m = 1 and 2; with two votes the nearest decides).
        assert!(!a.alpha_identified[4]);
        assert_eq!(a.alpha[4], a.alpha[2]);
        assert!(a.edf.iter().all(|e| *e > 0.0));
    }

    #[test]
    fn a_plan_equals_its_statistics_run_alone() {
        let y: Vec<f64> = (0..400).map(|k| ((k * 7919 + 13) % 101) as f64).collect();
        let z: Vec<f64> = y.iter().rev().map(|v| v * v).collect();
        let phases = column_phases(vec![y.iter().copied(), z.iter().copied()]).unwrap();
        let oadev = Statistic::Allan { overlapping: true };
        let plan = [(oadev, 1), (oadev, 8), (Statistic::TheoBR, 16)];
        let mixed = analyse_plan(&phases, &plan, &NEVER).unwrap();
        let avar = analyse(&phases, oadev, &[1, 8]).unwrap();
        let theobr = analyse(&phases, Statistic::TheoBR, &[16]).unwrap();
        assert_eq!(mixed.var[..4], avar.var[..]);
        assert_eq!(mixed.edf[..4], avar.edf[..]);
        assert_eq!(mixed.var[4..], theobr.var[..]);
        assert_eq!(mixed.terms, vec![399, 399, 385, 385, 385 * 8, 385 * 8]);
        // The slow single-tau path gives the same ThêoBR.
        let alone = Statistic::TheoBR.estimate(&phases[1].c, 16, &NEVER).var;
        assert!((alone - mixed.var[5]).abs() <= 1e-14 * alone);
    }

    #[test]
    fn overflow_is_an_error_not_nan() {
        let phases = column_phases(vec![[0.0, 9.5e153, 0.0].iter().copied()]).unwrap();
        let err = analyse(&phases, Statistic::Allan { overlapping: true }, &[1]).unwrap_err();
        assert!(err.to_string().contains("too large"), "{err}");
    }

    #[test]
    fn tau_too_long_is_an_error() {
        let phases = column_phases(vec![[1.0, 2.0, 4.0].iter().copied()]).unwrap();
        let err = analyse(&phases, Statistic::Allan { overlapping: true }, &[2]).unwrap_err();
        assert!(err.to_string().contains("does not fit"));
    }

    /// The SP 1065 terms straight from the samples, skipping every term whose
    /// window touches a NaN: (variance, terms).
    fn skipping_reference(y: &[f64], statistic: Statistic, m: usize) -> (f64, usize) {
        let block = |k: usize| y[k..k + m].iter().sum::<f64>();
        let mm = (m * m) as f64;
        let (window, stride, norm) = match statistic {
            Statistic::Allan { overlapping } => (2 * m, if overlapping { 1 } else { m }, 2.0 * mm),
            Statistic::Hadamard { overlapping } => {
                (3 * m, if overlapping { 1 } else { m }, 6.0 * mm)
            }
            _ => (3 * m - 1, 1, 2.0 * mm * mm),
        };
        let (mut sum, mut terms) = (0.0, 0);
        for k in (0..(y.len() + 1).saturating_sub(window)).step_by(stride) {
            if y[k..k + window].iter().any(|v| v.is_nan()) {
                continue;
            }
            let t = match statistic {
                Statistic::Allan { .. } => block(k + m) - block(k),
                Statistic::Hadamard { .. } => block(k + 2 * m) - 2.0 * block(k + m) + block(k),
                _ => (0..m).map(|i| block(k + i + m) - block(k + i)).sum(),
            };
            sum += t * t;
            terms += 1;
        }
        (sum / (norm * terms as f64), terms)
    }

    #[test]
    fn gapped_estimates_skip_every_term_touching_a_missing_sample() {
        let mut y = test_signals::noise(3000, 5);
        for k in [0, 17, 18, 19, 500, 1001, 1002, 2999] {
            y[k] = f64::NAN;
        }
        y[1500..1700].fill(f64::NAN);
        let phases = column_phases(vec![y.iter().copied()]).unwrap();
        assert_eq!(phases[0].gaps.as_ref().unwrap().missing, 208);
        let ms = [1, 2, 3, 7, 64, 300];
        for statistic in [
            Statistic::Allan { overlapping: true },
            Statistic::Allan { overlapping: false },
            Statistic::Hadamard { overlapping: true },
            Statistic::Hadamard { overlapping: false },
            Statistic::Modified,
        ] {
            let a = analyse(&phases, statistic, &ms).unwrap();
            for (t, &m) in ms.iter().enumerate() {
                let (var, terms) = skipping_reference(&y, statistic, m);
                assert_eq!(a.terms[t], terms, "{statistic:?} m={m}");
                assert!(
                    (a.var[t] / var - 1.0).abs() < 1e-11,
                    "{statistic:?} m={m}: {} vs {var}",
                    a.var[t]
                );
                assert!(a.edf[t] > 0.0 && a.edf[t] < terms as f64 * 2.0);
            }
            assert_eq!(a.missing, vec![208]);
        }
    }

    #[test]
    fn a_gap_at_the_end_is_the_shorter_record() {
        let y = test_signals::noise(2000, 9);
        let mut gapped = y.clone();
        gapped[1900..].fill(f64::NAN);
        let full = column_phases(vec![y[..1900].iter().copied()]).unwrap();
        let cut = column_phases(vec![gapped.iter().copied()]).unwrap();
        assert_eq!(full[0].c[..], cut[0].c[..1901]);
        for statistic in [Statistic::Allan { overlapping: true }, Statistic::Modified] {
            let a = analyse(&full, statistic, &[1, 4, 32]).unwrap();
            let b = analyse(&cut, statistic, &[1, 4, 32]).unwrap();
            assert_eq!(a.var, b.var);
            assert_eq!(a.terms, b.terms);
            assert_eq!(a.alpha, b.alpha);
            for (x, y) in a.edf.iter().zip(&b.edf) {
                assert!((x / y - 1.0).abs() < 1e-12, "{x} vs {y}");
            }
        }
    }

    #[test]
    fn edf_pools_the_runs_by_their_share_of_terms() {
        // Two equal runs: each has half the terms, so ν = 2·ν_run.
        let mut y = test_signals::noise(2001, 3);
        y[1000] = f64::NAN;
        let phases = column_phases(vec![y.iter().copied()]).unwrap();
        let a = analyse(&phases, Statistic::Allan { overlapping: true }, &[4]).unwrap();
        let est = uncertainty::edf::Estimator {
            d: 2,
            overlapping: true,
            modified: false,
        };
        let run = uncertainty::edf::greenhall_edf(a.alpha[0], est, 4, 1001);
        assert!((a.edf[0] / (2.0 * run) - 1.0).abs() < 1e-12);
        assert_eq!(a.terms, vec![2 * (1001 - 8)]);
    }

    #[test]
    fn gaps_longer_than_the_runs_leave_no_term() {
        let mut y = test_signals::noise(400, 1);
        for k in (0..400).step_by(10) {
            y[k] = f64::NAN;
        }
        let phases = column_phases(vec![y.iter().copied()]).unwrap();
        let a = analyse(&phases, Statistic::Allan { overlapping: true }, &[1, 4, 5]).unwrap();
        // 40 runs of 9 samples: 8 terms each at m = 1, 2 at m = 4, none at m = 5.
        assert_eq!(a.terms, vec![40 * 8, 40 * 2, 0]);
        assert!(a.var[2].is_nan() && a.edf[2].is_nan());
        assert!(a.var[1].is_finite());
    }

    #[test]
    fn the_total_family_refuses_gaps() {
        let mut y = test_signals::noise(400, 1);
        y[7] = f64::NAN;
        let phases = column_phases(vec![y.iter().copied()]).unwrap();
        for statistic in [Statistic::Total, Statistic::ModifiedTotal, Statistic::Theo1] {
            let err = analyse(&phases, statistic, &[2]).unwrap_err().to_string();
            assert!(
                err.contains("1 missing samples") && err.contains("cannot skip"),
                "{err}"
            );
        }
    }
}
