//! The statistics of the Allan module and everything that differs between them,
//! in one place: the public name, the terms an estimate averages, the estimator
//! it runs, how the noise type is identified, the EDF model, whether all taus can
//! be swept at once and whether missing samples can be skipped.
//!
//! Adding a statistic is a variant, a row of [`Statistic::ALL`], an arm in
//! [`Statistic::spec`], [`Statistic::terms`] and [`Statistic::estimate`] here,
//! and its estimator file under `estimators/`. The kernels below never see this
//! type, so the dependencies run one way: statistic → estimators → fast → sum.

use std::fmt;
use std::ops::Range;
use std::str::FromStr;

use super::estimators::difference::{self, DifferenceVariance};
use super::estimators::{mtot_htot, theo1, theobr, Estimate};
use super::fast::blocked::Difference;
use super::uncertainty::edf::{EdfModel, Estimator};
use crate::error::CoreError;
use crate::interrupt::Interrupt;

/// Which statistic to compute.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Statistic {
    /// Allan variance; `overlapping` selects stride 1 instead of stride m.
    Allan { overlapping: bool },
    /// Modified Allan variance (always overlapping).
    Modified,
    /// Hadamard variance; `overlapping` selects stride 1 instead of stride m.
    Hadamard { overlapping: bool },
    /// Total variance (SP 1065 eq. 25, reflection at both ends).
    Total,
    /// Modified total variance (SP 1065 eq. 27); m ≤ N/3.
    ModifiedTotal,
    /// Hadamard total variance (overlapping Hadamard at m = 1); m ≤ n/3.
    HadamardTotal,
    /// Theo1 (SP 1065 eq. 30), even m only; effective τ = 0.75·m·τ0.
    Theo1,
    /// ThêoBR (SP 1065 §5.2.15): Theo1 times the data's AVAR/Theo1 bias ratio
    /// (`estimators::theobr`); even 10 ≤ m < N and N ≥ 90 phase points.
    TheoBR,
}

/// What sets one statistic apart, besides its terms and estimator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spec {
    /// The name Python and the error messages use.
    pub name: &'static str,
    /// Most differences the lag-1 noise identification may take (2 for the Allan
    /// family, 3 for the Hadamard family, which converges for steeper noise).
    pub dmax: u32,
    /// Whether the estimate belongs to τ = 0.75·m·τ0 (Theo1 and ThêoBR), so that
    /// the noise type is identified at 0.75·m instead of m.
    pub effective_tau: bool,
    pub edf: EdfModel,
    /// For the overlapping Allan and Hadamard variances: the difference whose
    /// squares `fast::blocked` sums for all taus at once.
    pub blocked: Option<Difference>,
}

impl Statistic {
    /// Every statistic, in the order the bindings list their names.
    pub const ALL: [Statistic; 10] = [
        Statistic::Allan { overlapping: false },
        Statistic::Allan { overlapping: true },
        Statistic::Modified,
        Statistic::Hadamard { overlapping: false },
        Statistic::Hadamard { overlapping: true },
        Statistic::Total,
        Statistic::ModifiedTotal,
        Statistic::HadamardTotal,
        Statistic::Theo1,
        Statistic::TheoBR,
    ];

    /// The per-statistic constants.
    pub fn spec(self) -> Spec {
        let greenhall = |d, overlapping, modified| {
            EdfModel::Greenhall(Estimator {
                d,
                overlapping,
                modified,
            })
        };
        let spec = |name, dmax, edf| Spec {
            name,
            dmax,
            effective_tau: false,
            edf,
            blocked: None,
        };
        match self {
            Statistic::Allan { overlapping: false } => spec("adev", 2, greenhall(2, false, false)),
            Statistic::Allan { overlapping: true } => Spec {
                blocked: Some(Difference::Second),
                ..spec("oadev", 2, greenhall(2, true, false))
            },
            Statistic::Modified => spec("mdev", 2, greenhall(2, true, true)),
            Statistic::Hadamard { overlapping: false } => {
                spec("hdev", 3, greenhall(3, false, false))
            }
            Statistic::Hadamard { overlapping: true } => Spec {
                blocked: Some(Difference::Third),
                ..spec("ohdev", 3, greenhall(3, true, false))
            },
            Statistic::Total => spec("totdev", 2, EdfModel::Total),
            Statistic::ModifiedTotal => spec("mtotdev", 2, EdfModel::ModifiedTotal),
            // SP 1065 gives no EDF formula for HTOT; the overlapping Hadamard EDF is a
            // lower bound (HTOT is OHVAR with extra, reflected terms) and exact at m = 1.
            Statistic::HadamardTotal => spec("htotdev", 3, greenhall(3, true, false)),
            Statistic::Theo1 => Spec {
                effective_tau: true,
                ..spec("theo1", 2, EdfModel::Theo1)
            },
            Statistic::TheoBR => Spec {
                effective_tau: true,
                ..spec("theobr", 2, EdfModel::TheoBR)
            },
        }
    }

    /// The public name ("oadev", "theobr", …).
    pub fn name(self) -> &'static str {
        self.spec().name
    }

    /// The difference estimator this statistic is, if it is one: those, and only
    /// those, can leave out the terms a missing sample touches. The total family
    /// reflects or detrends the record around each point and cannot.
    pub fn difference_variance(self) -> Option<DifferenceVariance> {
        match self {
            Statistic::Allan { overlapping } => Some(DifferenceVariance::Allan { overlapping }),
            Statistic::Modified => Some(DifferenceVariance::Modified),
            Statistic::Hadamard { overlapping } => {
                Some(DifferenceVariance::Hadamard { overlapping })
            }
            _ => None,
        }
    }

    /// Whether terms can be left out where samples are missing.
    pub fn skips_gaps(self) -> bool {
        self.difference_variance().is_some()
    }

    /// Number of terms the estimator averages for `n_phase` phase points at
    /// averaging factor `m` (0 when the tau does not fit).
    pub fn terms(self, n_phase: usize, m: usize) -> usize {
        if let Some(estimator) = self.difference_variance() {
            return estimator.terms(n_phase, m);
        }
        match self {
            Statistic::Total => difference::total_terms(n_phase, m),
            Statistic::ModifiedTotal => mtot_htot::mtot_terms(n_phase, m),
            Statistic::HadamardTotal => mtot_htot::htot_terms(n_phase, m),
            Statistic::Theo1 => theo1::terms(n_phase, m),
            Statistic::TheoBR => theobr::terms(n_phase, m),
            Statistic::Allan { .. } | Statistic::Modified | Statistic::Hadamard { .. } => 0,
        }
    }

    /// Averaging factor at which the noise type is identified: m itself, or
    /// 0.75·m where the estimate belongs to that τ ([`Spec::effective_tau`]).
    pub fn noise_id_factor(self, m: usize) -> usize {
        if self.spec().effective_tau {
            ((3 * m) / 4).max(1)
        } else {
            m
        }
    }

    /// The variance at averaging factor `m` over the cumulative phase `c` of a
    /// record without missing samples; meaningless once `stop` is raised.
    pub fn estimate(self, c: &[f64], m: usize, stop: &Interrupt) -> Estimate {
        if let Some(estimator) = self.difference_variance() {
            return estimator.estimate(c, m);
        }
        let terms = self.terms(c.len(), m);
        if terms == 0 {
            return Estimate::EMPTY;
        }
        let var = match self {
            Statistic::Total => difference::totvar(c, m),
            Statistic::ModifiedTotal => mtot_htot::mtot_var(c, m, stop),
            Statistic::HadamardTotal => mtot_htot::htot_var(c, m, stop),
            Statistic::Theo1 => theo1::theo1_var(c, m, stop),
            // One tau alone pays for the whole bias ratio; `analyse` computes the
            // ratio once per channel instead.
            Statistic::TheoBR => match theobr::bias_ratio(c, stop) {
                Some(ratio) => ratio * theo1::theo1_var(c, m, stop),
                None => return Estimate::EMPTY,
            },
            Statistic::Allan { .. } | Statistic::Modified | Statistic::Hadamard { .. } => {
                return Estimate::EMPTY
            }
        };
        Estimate { var, terms }
    }

    /// The estimate over the terms inside the gap-free `segments` of a record with
    /// missing samples; `None` for statistics that cannot skip gaps.
    pub fn estimate_in_segments(
        self,
        c: &[f64],
        segments: &[Range<usize>],
        m: usize,
    ) -> Option<Estimate> {
        Some(
            self.difference_variance()?
                .estimate_in_segments(c, segments, m),
        )
    }
}

impl fmt::Display for Statistic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Statistic {
    type Err = CoreError;

    fn from_str(name: &str) -> Result<Self, Self::Err> {
        Statistic::ALL
            .into_iter()
            .find(|s| s.name() == name)
            .ok_or_else(|| {
                let names: Vec<&str> = Statistic::ALL.iter().map(|s| s.name()).collect();
                CoreError::InvalidArgument(format!(
                    "statistic must be one of {}; got {name:?}",
                    names.join(", ")
                ))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_round_trips() {
        for statistic in Statistic::ALL {
            assert_eq!(statistic.name().parse::<Statistic>(), Ok(statistic));
            assert_eq!(statistic.to_string(), statistic.name());
        }
        let mut names: Vec<&str> = Statistic::ALL.iter().map(|s| s.name()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Statistic::ALL.len(), "names must be distinct");
    }

    #[test]
    fn an_unknown_name_lists_the_known_ones() {
        let err = "avar".parse::<Statistic>().unwrap_err().to_string();
        assert_eq!(
            err,
            "statistic must be one of adev, oadev, mdev, hdev, ohdev, totdev, mtotdev, \
             htotdev, theo1, theobr; got \"avar\""
        );
    }

    #[test]
    fn only_the_difference_estimators_skip_gaps() {
        let skipping: Vec<&str> = Statistic::ALL
            .iter()
            .filter(|s| s.skips_gaps())
            .map(|s| s.name())
            .collect();
        assert_eq!(skipping, ["adev", "oadev", "mdev", "hdev", "ohdev"]);
    }
}
