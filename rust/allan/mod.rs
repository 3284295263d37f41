//! The Allan family over cumulative sums: estimates, noise identification and
//! equivalent degrees of freedom for many channels and taus at once.

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

use rayon::prelude::*;

use crate::error::{CoreError, CoreResult};
pub use variance::{Estimate, Statistic};

/// Results for `taus.len()` taus × `channels` channels, tau-major
/// (`var[t * channels + c]`), the layout of a C-ordered `(taus, channels)` array.
#[derive(Clone, Debug, PartialEq)]
pub struct Analysis {
    pub channels: usize,
    pub var: Vec<f64>,
    /// Terms per tau (the same for every channel).
    pub terms: Vec<usize>,
    /// Noise type α used for the EDF at each tau and channel.
    pub alpha: Vec<i32>,
    /// Whether α was identified at that tau (false: taken from the nearest tau
    /// where it was, or white FM, α = 0, when no tau could be identified).
    pub alpha_identified: Vec<bool>,
    pub edf: Vec<f64>,
}

/// Cumulative phases of several channels, computed in parallel. Each item yields
/// one channel's samples.
pub fn column_phases<I>(columns: Vec<I>) -> CoreResult<Vec<Vec<f64>>>
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
pub fn row_major_phases(data: &[f64], channels: usize) -> CoreResult<Vec<Vec<f64>>> {
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
fn transform_in_parallel(gathered: Vec<Vec<f64>>) -> CoreResult<Vec<Vec<f64>>> {
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
pub fn analyse(phases: &[Vec<f64>], statistic: Statistic, ms: &[usize]) -> CoreResult<Analysis> {
    let plan: Vec<(Statistic, usize)> = ms.iter().map(|&m| (statistic, m)).collect();
    analyse_plan(phases, &plan)
}

/// [`analyse`] with a statistic per tau: `plan[t]` = (statistic, m). ThêoH is
/// the plan of overlapping AVAR at its short taus and ThêoBR at its long ones.
/// Noise types missing at some taus are filled from the nearest identified taus
/// of the whole plan, so order the plan by τ.
pub fn analyse_plan(phases: &[Vec<f64>], plan: &[(Statistic, usize)]) -> CoreResult<Analysis> {
    let channels = phases.len();
    if channels == 0 {
        return Err(CoreError::InvalidArgument(
            "x must have at least one channel".into(),
        ));
    }
    let n_phase = phases[0].len();
    if phases.iter().any(|p| p.len() != n_phase) {
        return Err(CoreError::InvalidArgument(
            "all channels must have the same length".into(),
        ));
    }
    let terms: Vec<usize> = plan.iter().map(|&(s, m)| s.terms(n_phase, m)).collect();
    if let Some(pos) = terms.iter().position(|&t| t == 0) {
        return Err(CoreError::InvalidArgument(format!(
            "tau of {} samples does not fit in {} samples for this statistic",
            plan[pos].1,
            n_phase.saturating_sub(1)
        )));
    }
    let pairs: Vec<(usize, usize)> = (0..plan.len())
        .flat_map(|t| (0..channels).map(move |c| (t, c)))
        .collect();
    // The overlapping Allan and Hadamard variances sweep all their taus of a
    // channel at once (see `blocked`); every other statistic goes tau by tau.
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
            .map(|c| blocked::sums_of_squares(c, &ms, difference))
            .collect();
        for (k, &t) in taus.iter().enumerate() {
            for (c, channel_sums) in sums.iter().enumerate() {
                swept[t * channels + c] =
                    Some(statistic.variance_from_sum(channel_sums[k], plan[t].1, terms[t]));
            }
        }
    }
    // ThêoBR's bias ratio belongs to a channel, not a tau: computed once each.
    let ratios: Option<Vec<f64>> = if plan.iter().any(|(s, _)| *s == Statistic::TheoBR) {
        let refs: Vec<&[f64]> = phases.iter().map(|p| p.as_slice()).collect();
        theo::bias_ratios(&refs)
    } else {
        None
    };
    let per_pair: Vec<(f64, Option<i32>)> = pairs
        .par_iter()
        .enumerate()
        .map(|(i, &(t, c))| {
            let (statistic, m) = plan[t];
            let var = match (swept[i], statistic, &ratios) {
                (Some(v), _, _) => v,
                (None, Statistic::TheoBR, Some(r)) => {
                    r[c] * Statistic::Theo1.estimate(&phases[c], m).var
                }
                (None, _, _) => statistic.estimate(&phases[c], m).var,
            };
            let id_m = statistic.noise_id_factor(m);
            let (dmax, _) = noise_model_of(statistic);
            (var, noise_id::identify_alpha(&phases[c], id_m, dmax))
        })
        .collect();

    let mut var = Vec::with_capacity(pairs.len());
    let mut alpha = vec![0; pairs.len()];
    let mut alpha_identified = vec![false; pairs.len()];
    for (i, &(v, a)) in per_pair.iter().enumerate() {
        if !v.is_finite() {
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
            match noise_model_of(statistic).1 {
                EdfModel::Greenhall(est) => edf::greenhall_edf(alpha[i], est, m, n_phase),
                EdfModel::Total => edf::totvar_edf(alpha[i], m, n_samples),
                EdfModel::ModifiedTotal => edf::mtotvar_edf(alpha[i], m, n_samples),
                EdfModel::Theo1 => edf::theo1_edf(alpha[i], m, n_phase),
                EdfModel::TheoBR => theo::theobr_edf(alpha[i], m, n_phase),
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
    })
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
        assert_eq!(a.terms, vec![199, 197, 169, 73]);
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
        assert_eq!(mixed.terms, vec![399, 385, 385 * 8]);
        // The slow single-tau path gives the same ThêoBR.
        let alone = Statistic::TheoBR.estimate(&phases[1], 16).var;
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
        bad[4] = f64::NAN; // row 1, channel 1
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
}
