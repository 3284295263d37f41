//! The Allan-family variances over the cumulative phase `c` (n + 1 points, in
//! units of one sample period). Each function returns the variance at
//! τ = m·τ0 together with the number of terms in its sum, counted as Stable32
//! and allantools count them. References: NIST SP 1065 (Riley 2008), eqs. 6–25.

use std::ops::Range;

use super::blocked::Difference;
use super::sum::{sum_of_squared_combinations, sum_of_squares, Neumaier};
use super::theo;
use super::total;

/// A variance estimate and the number of terms it averages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    pub var: f64,
    pub terms: usize,
}

impl Estimate {
    const EMPTY: Estimate = Estimate {
        var: f64::NAN,
        terms: 0,
    };
}

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
    /// (`theo::bias_ratio`); even 10 ≤ m < N and N ≥ 90 phase points.
    TheoBR,
}

impl Statistic {
    /// Number of terms the estimator averages for `n_phase` phase points at
    /// averaging factor `m` (0 when the tau does not fit).
    pub fn terms(self, n_phase: usize, m: usize) -> usize {
        if m == 0 {
            return 0;
        }
        match self {
            Statistic::Allan { overlapping } => {
                strided_count(n_phase, 2 * m, stride(overlapping, m))
            }
            Statistic::Hadamard { overlapping } => {
                strided_count(n_phase, 3 * m, stride(overlapping, m))
            }
            Statistic::Modified => (n_phase + 1).saturating_sub(3 * m),
            Statistic::Total => {
                if m < n_phase && n_phase >= 3 {
                    n_phase - 2
                } else {
                    0
                }
            }
            // allantools' limits: m ≤ len(phase)/3 and m ≤ len(rate)/3.
            Statistic::ModifiedTotal => {
                if 3 * m <= n_phase {
                    n_phase + 1 - 3 * m
                } else {
                    0
                }
            }
            Statistic::HadamardTotal => {
                let n = n_phase.saturating_sub(1);
                if 3 * m > n {
                    0
                } else if m == 1 {
                    Statistic::Hadamard { overlapping: true }.terms(n_phase, 1)
                } else {
                    n + 1 - 3 * m
                }
            }
            // Terms counted as allantools counts them: (N − m) outer × m/2 inner.
            Statistic::Theo1 => {
                if m.is_multiple_of(2) && m < n_phase {
                    (n_phase - m) * (m / 2)
                } else {
                    0
                }
            }
            // Theo1's terms, over SP 1065's range 10 ≤ m ≤ N − 1, where the bias
            // ratio exists.
            Statistic::TheoBR => {
                if m >= 10 && theo::ratio_count(n_phase).is_some() {
                    Statistic::Theo1.terms(n_phase, m)
                } else {
                    0
                }
            }
        }
    }

    /// Averaging factor at which the noise type is identified: m itself, except
    /// for Theo1 whose estimate belongs to τ = 0.75·m·τ0.
    pub fn noise_id_factor(self, m: usize) -> usize {
        match self {
            Statistic::Theo1 | Statistic::TheoBR => ((3 * m) / 4).max(1),
            _ => m,
        }
    }

    /// For the overlapping Allan and Hadamard variances: the order of the
    /// difference whose squares `blocked::sums_of_squares` sums for all taus at once.
    pub fn blocked_difference(self) -> Option<Difference> {
        match self {
            Statistic::Allan { overlapping: true } => Some(Difference::Second),
            Statistic::Hadamard { overlapping: true } => Some(Difference::Third),
            _ => None,
        }
    }

    /// The variance from a sum of squared differences (see `blocked_difference`).
    pub fn variance_from_sum(self, sum: f64, m: usize, terms: usize) -> f64 {
        sum / (self.normaliser(m) * terms as f64)
    }

    /// Whether terms can be left out where samples are missing: the difference
    /// estimators can; the total family, whose terms reflect or detrend the
    /// record around each point, cannot.
    pub fn skips_gaps(self) -> bool {
        matches!(
            self,
            Statistic::Allan { .. } | Statistic::Modified | Statistic::Hadamard { .. }
        )
    }

    /// The divisor of a sum of squared terms per term: 2m² (Allan), 6m²
    /// (Hadamard), 2m⁴ (modified; its terms are sums of m second differences).
    fn normaliser(self, m: usize) -> f64 {
        let mf = m as f64;
        match self {
            Statistic::Hadamard { .. } => 6.0 * mf * mf,
            Statistic::Modified => 2.0 * mf.powi(4),
            _ => 2.0 * mf * mf,
        }
    }

    /// The sum of the `terms` squared terms of a difference estimator
    /// ([`Statistic::skips_gaps`]); `terms` = `self.terms(c.len(), m)` > 0.
    fn sum_of_terms(self, c: &[f64], m: usize, terms: usize) -> f64 {
        match self {
            Statistic::Allan { overlapping: true } => sum_of_squared_combinations(
                [&c[2 * m..2 * m + terms], &c[m..m + terms], &c[..terms]],
                [1.0, -2.0, 1.0],
            ),
            Statistic::Hadamard { overlapping: true } => sum_of_squared_combinations(
                [
                    &c[3 * m..3 * m + terms],
                    &c[2 * m..2 * m + terms],
                    &c[m..m + terms],
                    &c[..terms],
                ],
                [1.0, -3.0, 3.0, -1.0],
            ),
            Statistic::Allan { overlapping } => {
                let s = stride(overlapping, m);
                sum_of_squares(terms, |j| {
                    let k = j * s;
                    c[k + 2 * m] - 2.0 * c[k + m] + c[k]
                })
            }
            Statistic::Hadamard { overlapping } => {
                let s = stride(overlapping, m);
                sum_of_squares(terms, |j| {
                    let k = j * s;
                    c[k + 3 * m] - 3.0 * c[k + 2 * m] + 3.0 * c[k + m] - c[k]
                })
            }
            _ => modified_sum(c, m, terms),
        }
    }

    /// The phase points of one gap-free run of samples (`segment`, see
    /// [`super::phase::Gaps`]) on which this estimator's terms are exactly the
    /// record's terms that lie inside the run: c[a..=b], for the non-overlapping
    /// estimators from the first multiple of m on (their terms start at 0, m, 2m, …).
    pub fn segment_phase<'a>(self, c: &'a [f64], segment: &Range<usize>, m: usize) -> &'a [f64] {
        let start = match self {
            Statistic::Allan { overlapping: false }
            | Statistic::Hadamard { overlapping: false } => {
                segment.start.next_multiple_of(m.max(1))
            }
            _ => segment.start,
        };
        if start > segment.end {
            &[]
        } else {
            &c[start..=segment.end]
        }
    }

    /// The estimate over the terms that lie inside the gap-free `segments` of a
    /// record with missing samples ([`Statistic::skips_gaps`] statistics only:
    /// `None` for the others). No term: NaN.
    pub fn estimate_in_segments(
        self,
        c: &[f64],
        segments: &[Range<usize>],
        m: usize,
    ) -> Option<Estimate> {
        if !self.skips_gaps() {
            return None;
        }
        let mut sum = Neumaier::new();
        let mut terms = 0;
        for segment in segments {
            let part = self.segment_phase(c, segment, m);
            let t = self.terms(part.len(), m);
            if t > 0 {
                sum.add(self.sum_of_terms(part, m, t));
                terms += t;
            }
        }
        Some(Estimate {
            var: sum.value() / (self.normaliser(m) * terms as f64),
            terms,
        })
    }

    /// The variance at averaging factor `m` over the cumulative phase `c` of a
    /// record without missing samples.
    pub fn estimate(self, c: &[f64], m: usize) -> Estimate {
        let terms = self.terms(c.len(), m);
        if terms == 0 {
            return Estimate::EMPTY;
        }
        let mf = m as f64;
        let var = match self {
            Statistic::Allan { .. } | Statistic::Hadamard { .. } | Statistic::Modified => {
                self.sum_of_terms(c, m, terms) / (self.normaliser(m) * terms as f64)
            }
            Statistic::Total => total_sum(c, m) / (2.0 * mf * mf * terms as f64),
            Statistic::ModifiedTotal => total::mtot_var(c, m),
            Statistic::HadamardTotal if m == 1 => {
                Statistic::Hadamard { overlapping: true }.estimate(c, 1).var
            }
            Statistic::HadamardTotal => total::htot_var(c, m),
            Statistic::Theo1 => total::theo1_var(c, m),
            // One tau alone pays for the whole bias ratio; `analyse` computes the
            // ratio once per channel instead.
            Statistic::TheoBR => match theo::bias_ratio(c) {
                Some(ratio) => ratio * total::theo1_var(c, m),
                None => return Estimate::EMPTY,
            },
        };
        Estimate { var, terms }
    }
}

fn stride(overlapping: bool, m: usize) -> usize {
    if overlapping {
        1
    } else {
        m
    }
}

/// How many k = 0, s, 2s, … satisfy k + span ≤ n − 1.
fn strided_count(n: usize, span: usize, s: usize) -> usize {
    if n <= span {
        0
    } else {
        (n - 1 - span) / s + 1
    }
}

/// Σ_j [Σ_{i=j}^{j+m−1} (c_{i+2m} − 2c_{i+m} + c_i)]² for j = 0..terms. The inner
/// window sum slides by one sample per step; it is kept with compensation so that
/// millions of updates do not drift.
fn modified_sum(c: &[f64], m: usize, terms: usize) -> f64 {
    let second_difference = |i: usize| c[i + 2 * m] - 2.0 * c[i + m] + c[i];
    let mut window = Neumaier::new();
    for i in 0..m {
        window.add(second_difference(i));
    }
    let mut total = Neumaier::new();
    let mut block = 0.0;
    for j in 0..terms {
        let w = window.value();
        block += w * w;
        if j % 256 == 255 {
            total.add(block);
            block = 0.0;
        }
        if j + 1 < terms {
            window.add(second_difference(j + m));
            window.add(-second_difference(j));
        }
    }
    total.add(block);
    total.value()
}

/// Σ_{i=1}^{N−2} (x*_{i−m} − 2x*_i + x*_{i+m})² with x* the phase reflected about
/// both end points: x*_{−j} = 2x_0 − x_j and x*_{N−1+j} = 2x_{N−1} − x_{N−1−j}.
/// Where both neighbours lie inside the data (m ≤ i ≤ N−1−m) the sum is the plain
/// overlapping one; only the two ends need the reflection.
fn total_sum(c: &[f64], m: usize) -> f64 {
    let n = c.len();
    let last = n - 1;
    let reflected = |i: isize| -> f64 {
        if i < 0 {
            2.0 * c[0] - c[(-i) as usize]
        } else if i as usize > last {
            let j = i as usize - last;
            2.0 * c[last] - c[last - j]
        } else {
            c[i as usize]
        }
    };
    let mi = m as isize;
    let term = |i: usize| {
        let i = i as isize;
        reflected(i - mi) - 2.0 * c[i as usize] + reflected(i + mi)
    };
    // i runs over 1..=N−2; the straight middle is max(1, m)..=min(N−2, N−1−m).
    let lo = m.max(1);
    let hi = (n - 2).min(last.saturating_sub(m));
    if lo > hi {
        return sum_of_squares(n - 2, |j| term(j + 1));
    }
    let middle_terms = hi - lo + 1;
    let middle = sum_of_squared_combinations(
        [
            &c[lo - m..lo - m + middle_terms],
            &c[lo..lo + middle_terms],
            &c[lo + m..lo + m + middle_terms],
        ],
        [1.0, -2.0, 1.0],
    );
    let left = sum_of_squares(lo - 1, |j| term(j + 1));
    let right = sum_of_squares(n - 2 - hi, |j| term(hi + 1 + j));
    left + middle + right
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::phase::cumulative_phase;

    /// NIST SP 1065 NBS14 10-point frequency data.
    const NBS14: [f64; 9] = [
        892.0, 809.0, 823.0, 798.0, 671.0, 644.0, 883.0, 903.0, 677.0,
    ];

    fn dev(stat: Statistic, m: usize) -> f64 {
        let c = cumulative_phase(NBS14.iter().copied()).unwrap();
        stat.estimate(&c, m).var.sqrt()
    }

    fn close(a: f64, b: f64) {
        assert!((a - b).abs() <= 1e-4 * b.abs(), "{a} vs {b}");
    }

    #[test]
    fn nbs14_ten_point_reference_values() {
        close(dev(Statistic::Allan { overlapping: false }, 2), 115.8082);
        close(dev(Statistic::Allan { overlapping: true }, 1), 91.22945);
        close(dev(Statistic::Allan { overlapping: true }, 2), 85.95287);
        close(dev(Statistic::Modified, 2), 74.78849);
        close(dev(Statistic::Hadamard { overlapping: false }, 1), 70.80608);
        close(dev(Statistic::Hadamard { overlapping: false }, 2), 116.7980);
        close(dev(Statistic::Hadamard { overlapping: true }, 2), 85.61487);
        close(dev(Statistic::Total, 2), 93.90379);
    }

    #[test]
    fn taus_that_do_not_fit_have_no_terms() {
        let c = cumulative_phase(NBS14.iter().copied()).unwrap();
        let e = Statistic::Allan { overlapping: true }.estimate(&c, 5);
        assert_eq!(e.terms, 0);
        assert!(e.var.is_nan());
        assert_eq!(Statistic::Modified.terms(10, 4), 0);
        assert_eq!(Statistic::Modified.terms(10, 3), 2);
    }
}
