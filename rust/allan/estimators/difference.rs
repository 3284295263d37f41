//! The difference estimators over the cumulative phase `c` (n + 1 points, in
//! units of one sample period): the Allan, modified Allan and Hadamard variances,
//! which can leave out the terms a missing sample touches, and the total variance
//! TOTVAR, the overlapping Allan variance of the phase reflected about both ends.
//! Terms are counted as Stable32 and allantools count them. References: NIST
//! SP 1065 (Riley 2008), eqs. 6–25.
//!
//! Cost. One pass over the phase per tau, O(n): the overlapping sums stream fixed
//! combinations of three or four shifted slices (`sum_of_squared_combinations`),
//! the modified variance slides a window sum. `fast::blocked` does all taus of the
//! overlapping Allan and Hadamard variances in one sweep instead.
//!
//! Digits. Squares are summed in plain blocks of 256 (relative error below 256·ε,
//! the terms being non-negative) and the blocks with compensation; the modified
//! variance's window sum is compensated so that millions of updates do not drift.

use std::ops::Range;

use super::Estimate;
use crate::allan::sum::{sum_of_squared_combinations, sum_of_squares, Neumaier};

/// A variance made of squared differences of the phase, one term per start
/// index; the only estimators that can skip gaps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DifferenceVariance {
    /// Allan variance; `overlapping` selects stride 1 instead of stride m.
    Allan { overlapping: bool },
    /// Modified Allan variance (always overlapping).
    Modified,
    /// Hadamard variance; `overlapping` selects stride 1 instead of stride m.
    Hadamard { overlapping: bool },
}

impl DifferenceVariance {
    /// Number of terms for `n_phase` phase points at averaging factor `m` (0 when
    /// the tau does not fit).
    pub fn terms(self, n_phase: usize, m: usize) -> usize {
        if m == 0 {
            return 0;
        }
        match self {
            DifferenceVariance::Allan { overlapping } => {
                strided_count(n_phase, 2 * m, stride(overlapping, m))
            }
            DifferenceVariance::Hadamard { overlapping } => {
                strided_count(n_phase, 3 * m, stride(overlapping, m))
            }
            DifferenceVariance::Modified => (n_phase + 1).saturating_sub(3 * m),
        }
    }

    /// The variance from a sum of `terms` squared terms at averaging factor m.
    pub fn variance_from_sum(self, sum: f64, m: usize, terms: usize) -> f64 {
        sum / (self.normaliser(m) * terms as f64)
    }

    /// The divisor of a sum of squared terms per term: 2m² (Allan), 6m²
    /// (Hadamard), 2m⁴ (modified; its terms are sums of m second differences).
    fn normaliser(self, m: usize) -> f64 {
        let mf = m as f64;
        match self {
            DifferenceVariance::Hadamard { .. } => 6.0 * mf * mf,
            DifferenceVariance::Modified => 2.0 * mf.powi(4),
            DifferenceVariance::Allan { .. } => 2.0 * mf * mf,
        }
    }

    /// The sum of the `terms` squared terms; `terms` = `self.terms(c.len(), m)` > 0.
    fn sum_of_terms(self, c: &[f64], m: usize, terms: usize) -> f64 {
        match self {
            DifferenceVariance::Allan { overlapping: true } => sum_of_squared_combinations(
                [&c[2 * m..2 * m + terms], &c[m..m + terms], &c[..terms]],
                [1.0, -2.0, 1.0],
            ),
            DifferenceVariance::Hadamard { overlapping: true } => sum_of_squared_combinations(
                [
                    &c[3 * m..3 * m + terms],
                    &c[2 * m..2 * m + terms],
                    &c[m..m + terms],
                    &c[..terms],
                ],
                [1.0, -3.0, 3.0, -1.0],
            ),
            DifferenceVariance::Allan { overlapping } => {
                let s = stride(overlapping, m);
                sum_of_squares(terms, |j| {
                    let k = j * s;
                    c[k + 2 * m] - 2.0 * c[k + m] + c[k]
                })
            }
            DifferenceVariance::Hadamard { overlapping } => {
                let s = stride(overlapping, m);
                sum_of_squares(terms, |j| {
                    let k = j * s;
                    c[k + 3 * m] - 3.0 * c[k + 2 * m] + 3.0 * c[k + m] - c[k]
                })
            }
            DifferenceVariance::Modified => modified_sum(c, m, terms),
        }
    }

    /// The phase points of one gap-free run of samples (`segment`, see
    /// [`crate::allan::phase::Gaps`]) on which this estimator's terms are exactly
    /// the record's terms that lie inside the run: c[a..=b], for the
    /// non-overlapping estimators from the first multiple of m on (their terms
    /// start at 0, m, 2m, …).
    pub fn segment_phase<'a>(self, c: &'a [f64], segment: &Range<usize>, m: usize) -> &'a [f64] {
        let start = match self {
            DifferenceVariance::Allan { overlapping: false }
            | DifferenceVariance::Hadamard { overlapping: false } => {
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
    /// record with missing samples. No term: NaN.
    pub fn estimate_in_segments(self, c: &[f64], segments: &[Range<usize>], m: usize) -> Estimate {
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
        Estimate {
            var: sum.value() / (self.normaliser(m) * terms as f64),
            terms,
        }
    }

    /// The variance at averaging factor `m` over the cumulative phase `c` of a
    /// record without missing samples.
    pub fn estimate(self, c: &[f64], m: usize) -> Estimate {
        let terms = self.terms(c.len(), m);
        if terms == 0 {
            return Estimate::EMPTY;
        }
        Estimate {
            var: self.variance_from_sum(self.sum_of_terms(c, m, terms), m, terms),
            terms,
        }
    }
}

/// The overlapping Allan variance at averaging factor m (NaN when it does not fit).
pub fn oavar(c: &[f64], m: usize) -> f64 {
    DifferenceVariance::Allan { overlapping: true }
        .estimate(c, m)
        .var
}

/// Terms of TOTVAR: the N − 2 inner phase points, for 1 ≤ m < N.
pub fn total_terms(n_phase: usize, m: usize) -> usize {
    if m >= 1 && m < n_phase && n_phase >= 3 {
        n_phase - 2
    } else {
        0
    }
}

/// Total variance at averaging factor m; `total_terms(c.len(), m)` > 0.
pub fn totvar(c: &[f64], m: usize) -> f64 {
    let mf = m as f64;
    total_sum(c, m) / (2.0 * mf * mf * total_terms(c.len(), m) as f64)
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

    fn nbs14_phase() -> Vec<f64> {
        cumulative_phase(NBS14.iter().copied()).unwrap()
    }

    fn dev(estimator: DifferenceVariance, m: usize) -> f64 {
        estimator.estimate(&nbs14_phase(), m).var.sqrt()
    }

    fn close(a: f64, b: f64) {
        assert!((a - b).abs() <= 1e-4 * b.abs(), "{a} vs {b}");
    }

    #[test]
    fn nbs14_ten_point_reference_values() {
        use DifferenceVariance::{Allan, Hadamard, Modified};
        close(dev(Allan { overlapping: false }, 2), 115.8082);
        close(dev(Allan { overlapping: true }, 1), 91.22945);
        close(dev(Allan { overlapping: true }, 2), 85.95287);
        close(dev(Modified, 2), 74.78849);
        close(dev(Hadamard { overlapping: false }, 1), 70.80608);
        close(dev(Hadamard { overlapping: false }, 2), 116.7980);
        close(dev(Hadamard { overlapping: true }, 2), 85.61487);
        close(totvar(&nbs14_phase(), 2).sqrt(), 93.90379);
        close(oavar(&nbs14_phase(), 2).sqrt(), 85.95287);
    }

    #[test]
    fn taus_that_do_not_fit_have_no_terms() {
        let e = DifferenceVariance::Allan { overlapping: true }.estimate(&nbs14_phase(), 5);
        assert_eq!(e.terms, 0);
        assert!(e.var.is_nan());
        assert_eq!(DifferenceVariance::Modified.terms(10, 4), 0);
        assert_eq!(DifferenceVariance::Modified.terms(10, 3), 2);
        assert_eq!(total_terms(10, 10), 0);
        assert_eq!(total_terms(10, 9), 8);
    }
}
