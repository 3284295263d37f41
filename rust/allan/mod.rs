//! The Allan family over cumulative sums: estimates, noise identification and
//! equivalent degrees of freedom for many channels and taus at once.
//!
//! Missing samples (NaN) are gaps. The difference estimators (Allan, modified
//! Allan, Hadamard; [`Statistic::skips_gaps`]) leave out every term whose window
//! touches a missing sample and count only the terms used; the total family
//! refuses gapped records. With gaps, the noise type is identified on the longest
//! gap-free run and the EDF pools the runs: each run's estimate has Greenhall's
//! EDF ν_s for its length and carries the share w_s of the terms, so, treating
//! the runs as independent, 1/ν = Σ w_s²/ν_s (ν of the whole record when there is
//! no gap). A record without NaN takes exactly the gap-free code path.

pub mod blocked;
pub mod edf;
pub mod noise_id;
pub mod phase;
pub mod reflected;
pub mod sliding;
pub mod sum;
#[cfg(test)]
mod test_signals;
pub mod theo;
pub mod theo1;
pub mod total;
pub mod variance;

use std::collections::BTreeMap;
use std::ops::Range;

use rayon::prelude::*;

use crate::error::{CoreError, CoreResult};
pub use phase::{Gaps, Phase};
pub use variance::{Estimate, Statistic};

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

/// Cumulative phases of several channels, computed in parallel. Each item yields
/// one channel's samples.
pub fn column_phases<I>(columns: Vec<I>) -> CoreResult<Vec<Phase>>
where
    I: Iterator<Item = f64> + Send,
{
    let gathered = columns.into_par_iter().map(phase::gather).collect();
    transform_in_parallel(gathered)
}

/// Cumulative phases of the columns of a C-ordered `(n, channels)` array given as
/// its row-major data: one pass over the rows scatters the samples into the
/// channels' phase vectors (each column gathered separately would stream the whole
/// array once per channel), then the channels are transformed in parallel.
pub fn row_major_phases(data: &[f64], channels: usize) -> CoreResult<Vec<Phase>> {
    if channels == 0 || !data.len().is_multiple_of(channels) {
        return Err(CoreError::InvalidArgument(format!(
            "x has {} values, not a whole number of rows of {channels} channels",
            data.len()
        )));
    }
    let n = data.len() / channels;
    let mut phases: Vec<Vec<f64>> = (0..channels)
        .map(|_| {
            let mut phase = Vec::with_capacity(n + 1);
            crate::memory::advise_huge_pages(&phase);
            phase.resize(n + 1, 0.0);
            phase
        })
        .collect();
    for (i, row) in data.chunks_exact(channels).enumerate() {
        for (phase, &value) in phases.iter_mut().zip(row) {
            phase[i + 1] = value;
        }
    }
    transform_in_parallel(phases)
}

/// Turns gathered samples (behind a leading slot) into cumulative phases, one
/// channel per task; errors name the channel when there are several.
fn transform_in_parallel(gathered: Vec<Vec<f64>>) -> CoreResult<Vec<Phase>> {
    let several = gathered.len() > 1;
    gathered
        .into_par_iter()
        .enumerate()
        .map(|(channel, phase)| {
            phase::into_cumulative_phase(phase).map_err(|e| match e {
                CoreError::InvalidArgument(msg) if several => {
                    CoreError::InvalidArgument(format!("{msg} (channel {channel})"))
                }
                other => other,
            })
        })
        .collect()
}

/// Estimates the statistic at every averaging factor in `ms` for every phase,
/// identifies the noise type and computes the EDF. Work is spread over
/// (channel, tau) pairs.
pub fn analyse(phases: &[Phase], statistic: Statistic, ms: &[usize]) -> CoreResult<Analysis> {
    let plan: Vec<(Statistic, usize)> = ms.iter().map(|&m| (statistic, m)).collect();
    analyse_plan(phases, &plan)
}

/// [`analyse`] with a statistic per tau: `plan[t]` = (statistic, m). ThêoH is
/// the plan of overlapping AVAR at its short taus and ThêoBR at its long ones.
/// Noise types missing at some taus are filled from the nearest identified taus
/// of the whole plan, so order the plan by τ.
pub fn analyse_plan(phases: &[Phase], plan: &[(Statistic, usize)]) -> CoreResult<Analysis> {
    let channels = phases.len();
    if channels == 0 {
        return Err(CoreError::InvalidArgument(
            "x must have at least one channel".into(),
        ));
    }
    let n_phase = phases[0].c.len();
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
    let full_terms: Vec<usize> = plan.iter().map(|&(s, m)| s.terms(n_phase, m)).collect();
    if let Some(pos) = full_terms.iter().position(|&t| t == 0) {
        return Err(CoreError::InvalidArgument(format!(
            "tau of {} samples does not fit in {} samples for this statistic",
            plan[pos].1,
            n_phase.saturating_sub(1)
        )));
    }
    let pairs: Vec<(usize, usize)> = (0..plan.len())
        .flat_map(|t| (0..channels).map(move |c| (t, c)))
        .collect();
    // With gaps: how many runs have each length (in phase points) that holds a term.
    let runs: Vec<Option<BTreeMap<usize, usize>>> = pairs
        .iter()
        .map(|&(t, c)| {
            let (s, m) = plan[t];
            let g = phases[c].gaps.as_ref()?;
            Some(segment_lengths(s, &phases[c].c, &g.segments, m))
        })
        .collect();
    let terms: Vec<usize> = pairs
        .iter()
        .zip(&runs)
        .map(|(&(t, _), lengths)| {
            let (s, m) = plan[t];
            match lengths {
                None => full_terms[t],
                Some(lengths) => lengths.iter().map(|(&l, &n)| n * s.terms(l, m)).sum(),
            }
        })
        .collect();
    // The overlapping Allan and Hadamard variances sweep all their taus of a
    // channel at once (see `blocked`, run over each gap-free run); every other
    // statistic goes tau by tau.
    let mut swept: Vec<Option<f64>> = vec![None; pairs.len()];
    let mut blocked: Vec<Statistic> = Vec::new();
    for &(s, _) in plan {
        if s.blocked_difference().is_some() && !blocked.contains(&s) {
            blocked.push(s);
        }
    }
    for statistic in blocked {
        let Some(difference) = statistic.blocked_difference() else {
            continue;
        };
        let taus: Vec<usize> = (0..plan.len())
            .filter(|&t| plan[t].0 == statistic)
            .collect();
        let ms: Vec<usize> = taus.iter().map(|&t| plan[t].1).collect();
        let sums: Vec<Vec<f64>> = phases
            .par_iter()
            .map(|p| match &p.gaps {
                None => blocked::sums_of_squares(&p.c, &ms, difference),
                Some(g) => sums_over_segments(&p.c, &g.segments, &ms, difference),
            })
            .collect();
        for (k, &t) in taus.iter().enumerate() {
            for (c, channel_sums) in sums.iter().enumerate() {
                let i = t * channels + c;
                swept[i] = Some(statistic.variance_from_sum(channel_sums[k], plan[t].1, terms[i]));
            }
        }
    }
    // ThêoBR's bias ratio belongs to a channel, not a tau: computed once each.
    let ratios: Option<Vec<f64>> = if plan.iter().any(|(s, _)| *s == Statistic::TheoBR) {
        let refs: Vec<&[f64]> = phases.iter().map(|p| p.c.as_slice()).collect();
        theo::bias_ratios(&refs)
    } else {
        None
    };
    let per_pair: Vec<(f64, Option<i32>)> = pairs
        .par_iter()
        .enumerate()
        .map(|(i, &(t, c))| {
            let (statistic, m) = plan[t];
            let phase = &phases[c];
            let var = match (swept[i], statistic, &ratios, &phase.gaps) {
                (Some(v), _, _, _) => v,
                (None, Statistic::TheoBR, Some(r), _) => {
                    r[c] * Statistic::Theo1.estimate(&phase.c, m).var
                }
                (None, _, _, None) => statistic.estimate(&phase.c, m).var,
                (None, _, _, Some(g)) => statistic
                    .estimate_in_segments(&phase.c, &g.segments, m)
                    .map_or(f64::NAN, |e| e.var),
            };
            let id_m = statistic.noise_id_factor(m);
            let (dmax, _) = noise_model_of(statistic);
            (
                var,
                noise_id::identify_alpha(identification_phase(phase), id_m, dmax),
            )
        })
        .collect();

    let mut var = Vec::with_capacity(pairs.len());
    let mut alpha = vec![0; pairs.len()];
    let mut alpha_identified = vec![false; pairs.len()];
    for (i, &(v, a)) in per_pair.iter().enumerate() {
        if !v.is_finite() && terms[i] > 0 {
            let (t, c) = pairs[i];
            return Err(CoreError::Numerical(format!(
                "x is too large in magnitude: the variance at m = {} overflows double \
                 precision (channel {c}); rescale x",
                plan[t].1
            )));
        }
        var.push(v);
        if let Some(a) = a {
            alpha[i] = a;
            alpha_identified[i] = true;
        }
    }
    for c in 0..channels {
        fill_from_nearest(&mut alpha, &alpha_identified, c, channels, plan.len());
    }
    let n_samples = n_phase - 1;
    let edf = pairs
        .iter()
        .enumerate()
        .map(|(i, &(t, _))| {
            let (statistic, m) = plan[t];
            match (noise_model_of(statistic).1, &runs[i]) {
                (EdfModel::Greenhall(est), Some(lengths)) => {
                    edf_over_segments(lengths, terms[i], statistic, m, |len| {
                        edf::greenhall_edf(alpha[i], est, m, len)
                    })
                }
                (EdfModel::Greenhall(est), None) => edf::greenhall_edf(alpha[i], est, m, n_phase),
                (EdfModel::Total, _) => edf::totvar_edf(alpha[i], m, n_samples),
                (EdfModel::ModifiedTotal, _) => edf::mtotvar_edf(alpha[i], m, n_samples),
                (EdfModel::Theo1, _) => edf::theo1_edf(alpha[i], m, n_phase),
                (EdfModel::TheoBR, _) => theo::theobr_edf(alpha[i], m, n_phase),
            }
        })
        .collect();
    Ok(Analysis {
        channels,
        var,
        terms,
        alpha,
        alpha_identified,
        edf,
        missing: phases
            .iter()
            .map(|p| p.gaps.as_ref().map_or(0, |g| g.missing))
            .collect(),
    })
}

/// [`blocked::sums_of_squares`] over the gap-free runs of a record: the terms
/// inside one run are exactly those of the blocked sweep over its phase points.
fn sums_over_segments(
    c: &[f64],
    segments: &[Range<usize>],
    ms: &[usize],
    difference: blocked::Difference,
) -> Vec<f64> {
    let partials: Vec<Vec<f64>> = segments
        .par_iter()
        .map(|s| blocked::sums_of_squares(&c[s.start..=s.end], ms, difference))
        .collect();
    let mut totals = vec![sum::Neumaier::new(); ms.len()];
    for partial in &partials {
        for (total, value) in totals.iter_mut().zip(partial) {
            total.add(*value);
        }
    }
    totals.iter().map(sum::Neumaier::value).collect()
}

/// The phase the noise type is identified on: the whole record, or with gaps
/// its longest gap-free run (the lag-1 method needs an unbroken series).
fn identification_phase(phase: &Phase) -> &[f64] {
    match phase.gaps.as_ref().and_then(Gaps::longest) {
        None => &phase.c,
        Some(s) => &phase.c[s.start..=s.end],
    }
}

/// Phase points → how many runs have that many, over the runs where the
/// estimator has terms (see [`Statistic::segment_phase`]).
fn segment_lengths(
    statistic: Statistic,
    c: &[f64],
    segments: &[Range<usize>],
    m: usize,
) -> BTreeMap<usize, usize> {
    let mut lengths = BTreeMap::new();
    for s in segments {
        let len = statistic.segment_phase(c, s, m).len();
        if statistic.terms(len, m) > 0 {
            *lengths.entry(len).or_insert(0) += 1;
        }
    }
    lengths
}

/// The EDF of an estimate pooled over runs with `lengths` phase points (see the
/// module notes): 1/ν = Σ_s (T_s/T)²/ν_s. NaN without terms.
fn edf_over_segments(
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

/// How the EDF of an estimator is obtained.
#[derive(Clone, Copy, Debug)]
enum EdfModel {
    /// Greenhall's algorithm for this difference estimator.
    Greenhall(edf::Estimator),
    /// SP 1065 Table 7 (TOTVAR).
    Total,
    /// SP 1065 Table 8 (MTOT, and TTOT which is MTOT scaled).
    ModifiedTotal,
    /// SP 1065 Theo1 formulas (Howe & Tasset).
    Theo1,
    /// Theo1's EDF combined with the scatter of ThêoBR's bias ratio.
    TheoBR,
}

/// Maximum differencing for noise identification and the EDF model.
fn noise_model_of(statistic: Statistic) -> (u32, EdfModel) {
    use edf::Estimator;
    let ohvar = Estimator {
        d: 3,
        overlapping: true,
        modified: false,
    };
    match statistic {
        Statistic::Allan { overlapping } => (
            2,
            EdfModel::Greenhall(Estimator {
                d: 2,
                overlapping,
                modified: false,
            }),
        ),
        Statistic::Modified => (
            2,
            EdfModel::Greenhall(Estimator {
                d: 2,
                overlapping: true,
                modified: true,
            }),
        ),
        Statistic::Hadamard { overlapping } => (
            3,
            EdfModel::Greenhall(Estimator {
                d: 3,
                overlapping,
                modified: false,
            }),
        ),
        Statistic::Total => (2, EdfModel::Total),
        Statistic::ModifiedTotal => (2, EdfModel::ModifiedTotal),
        // SP 1065 gives no EDF formula for HTOT; the overlapping Hadamard EDF is a
        // lower bound (HTOT is OHVAR with extra, reflected terms) and exact at m = 1.
        Statistic::HadamardTotal => (3, EdfModel::Greenhall(ohvar)),
        Statistic::Theo1 => (2, EdfModel::Theo1),
        Statistic::TheoBR => (2, EdfModel::TheoBR),
    }
}

/// Where a tau's series was too short to identify, use the median α of the (up
/// to) three nearest identified taus of the same channel; with none at all, white
/// FM (α = 0). The last identifiable taus rest on 30–60 points each, so one of
/// them is misidentified now and then; the median keeps a single outlier from
/// deciding the noise type (and so the EDF) of every longer tau.
fn fill_from_nearest(alpha: &mut [i32], known: &[bool], c: usize, channels: usize, taus: usize) {
    let idx = |t: usize| t * channels + c;
    let identified: Vec<usize> = (0..taus).filter(|&t| known[idx(t)]).collect();
    for t in 0..taus {
        if known[idx(t)] {
            continue;
        }
        let mut nearest = identified.clone();
        nearest.sort_by_key(|&k| (k.abs_diff(t), k));
        let mut votes: Vec<i32> = nearest.iter().take(3).map(|&k| alpha[idx(k)]).collect();
        alpha[idx(t)] = match votes.len() {
            0 => 0,
            1 | 2 => votes[0],
            _ => {
                votes.sort_unstable();
                votes[1]
            }
        };
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
    fn one_misidentified_tau_does_not_decide_the_longer_ones() {
        let mut alpha = vec![0, 0, 0, 1, 0, 0];
        let known = vec![true, true, true, true, false, false];
        fill_from_nearest(&mut alpha, &known, 0, 1, 6);
        assert_eq!(alpha, vec![0, 0, 0, 1, 0, 0]);
        let mut alpha = vec![-2, -2, -2, 0, 0];
        let known = vec![true, true, true, false, false];
        fill_from_nearest(&mut alpha, &known, 0, 1, 5);
        assert_eq!(alpha, vec![-2, -2, -2, -2, -2]);
    }

    #[test]
    fn a_plan_equals_its_statistics_run_alone() {
        let y: Vec<f64> = (0..400).map(|k| ((k * 7919 + 13) % 101) as f64).collect();
        let z: Vec<f64> = y.iter().rev().map(|v| v * v).collect();
        let phases = column_phases(vec![y.iter().copied(), z.iter().copied()]).unwrap();
        let oadev = Statistic::Allan { overlapping: true };
        let plan = [(oadev, 1), (oadev, 8), (Statistic::TheoBR, 16)];
        let mixed = analyse_plan(&phases, &plan).unwrap();
        let avar = analyse(&phases, oadev, &[1, 8]).unwrap();
        let theobr = analyse(&phases, Statistic::TheoBR, &[16]).unwrap();
        assert_eq!(mixed.var[..4], avar.var[..]);
        assert_eq!(mixed.edf[..4], avar.edf[..]);
        assert_eq!(mixed.var[4..], theobr.var[..]);
        assert_eq!(mixed.terms, vec![399, 399, 385, 385, 385 * 8, 385 * 8]);
        // The slow single-tau path gives the same ThêoBR.
        let alone = Statistic::TheoBR.estimate(&phases[1].c, 16).var;
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

    #[test]
    fn row_major_phases_equal_column_phases() {
        let data: Vec<f64> = (0..300).map(|k| ((k * 7919) % 101) as f64 - 50.0).collect();
        let rows = row_major_phases(&data, 3).unwrap();
        let columns = column_phases(
            (0..3)
                .map(|c| data.iter().skip(c).step_by(3).copied())
                .collect(),
        )
        .unwrap();
        assert_eq!(rows, columns);
        assert!(row_major_phases(&data, 7).is_err());
        let mut bad = data.clone();
        bad[4] = f64::INFINITY; // row 1, channel 1
        let err = row_major_phases(&bad, 3).unwrap_err().to_string();
        assert!(
            err.contains("sample 1") && err.contains("channel 1"),
            "{err}"
        );
    }

    #[test]
    fn non_finite_values_name_the_channel() {
        let a = [1.0, 2.0];
        let b = [1.0, f64::INFINITY];
        let err = column_phases(vec![a.iter().copied(), b.iter().copied()]).unwrap_err();
        assert!(err.to_string().contains("channel 1"), "{err}");
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
        let est = edf::Estimator {
            d: 2,
            overlapping: true,
            modified: false,
        };
        let run = edf::greenhall_edf(a.alpha[0], est, 4, 1001);
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
