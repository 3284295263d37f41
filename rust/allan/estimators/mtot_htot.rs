//! The modified total (MTOT) and Hadamard total (HTOT) variances over the
//! cumulative phase `c` (n + 1 points, in units of one sample period; phase
//! x = τ0·c, rate samples y_k = c_{k+1} − c_k).
//!
//! Definitions follow NIST SP 1065 (Riley 2008) eqs. 27 and 29 and Howe's
//! papers as implemented by allantools and Stable32:
//!
//! - MTOT: for each of the N − 3m + 1 phase subsequences of 3m points, remove
//!   the linear trend given by the means of its first and last halves, extend it
//!   by uninverted even reflection to 9m points and average the 6m squared
//!   second differences of m-point means; σ² = Σ / (2 m² (N − 3m + 1)).
//! - HTOT: the same on the *rate* samples (n − 3m + 1 subsequences), with the
//!   Hadamard normalisation (divisor 6); at m = 1 the overlapping Hadamard
//!   variance is used, as Stable32 and allantools do.
//!
//! Cost. Every subsequence is detrended and reflected on its own, so the direct
//! form costs O(n·m) per tau, 15m operations per subsequence; from
//! [`REFLECTED_FROM`] on, `fast::reflected` expands the same sum in O(n). A
//! formulation through global prefix sums of products (c_k·c_{k+l}) exists on
//! paper, but it expands the squares into products of the raw phase, which cancel
//! catastrophically (for random-walk FM on 10⁶ points the terms are ~10¹² times
//! larger than their sum), and the reflections make anti-diagonal sums
//! (Σ_j c_{i+j}·c_{i+m−j}) that no one-dimensional prefix sum provides. Here every
//! subsequence works on offset-removed local values instead, which keeps all
//! digits; the subsequences of one tau are spread over threads.

use super::difference::DifferenceVariance;
use super::sum_over_subsequences;
use crate::allan::fast::reflected::reflected_sum;
use crate::allan::sum::Neumaier;
use crate::interrupt::Interrupt;

/// Averaging factors from here on use `fast::reflected`'s O(n) expansion; below
/// it the direct sum is cheaper and the expansion's blocks would be too short to
/// keep their digits.
pub const REFLECTED_FROM: usize = 16;

/// Terms of MTOT, N − 3m + 1, within allantools' limit m ≤ N/3.
pub fn mtot_terms(n_phase: usize, m: usize) -> usize {
    if m >= 1 && 3 * m <= n_phase {
        n_phase + 1 - 3 * m
    } else {
        0
    }
}

/// Terms of HTOT, n − 3m + 1 rate subsequences within m ≤ n/3 (allantools'
/// limit); at m = 1 those of the overlapping Hadamard variance.
pub fn htot_terms(n_phase: usize, m: usize) -> usize {
    let n = n_phase.saturating_sub(1);
    if m == 0 || 3 * m > n {
        0
    } else if m == 1 {
        DifferenceVariance::Hadamard { overlapping: true }.terms(n_phase, 1)
    } else {
        n + 1 - 3 * m
    }
}

/// Σ over the 6m window positions j of D_j² for one subsequence whose prefix
/// sums (of the detrended values z, local to the subsequence) are `zp`
/// (3m + 1 values, zp[0] = 0). The subsequence is extended by uninverted even
/// reflection to xstar = [flip(z), z, flip(z)] (9m values) and
/// D_j = S(j) − 2S(j + m) + S(j + 2m), S(a) = Σ xstar[a..a+m).
/// `p` is scratch space for the 9m + 1 prefix sums of xstar.
fn reflected_second_differences(zp: &[f64], m: usize, p: &mut [f64]) -> f64 {
    let l = 3 * m;
    let total = zp[l];
    // P(t) = Σ_{τ<t} xstar_τ, piece by piece.
    for t in 0..=l {
        p[t] = total - zp[l - t];
    }
    for t in 1..=l {
        p[l + t] = total + zp[t];
    }
    for t in 1..=l {
        p[2 * l + t] = 3.0 * total - zp[l - t];
    }
    let span = 6 * m;
    let p0 = &p[..span];
    let p1 = &p[m..m + span];
    let p2 = &p[2 * m..2 * m + span];
    let p3 = &p[3 * m..3 * m + span];
    let mut lanes = [0.0f64; 4];
    let mut j = 0;
    while j + 4 <= span {
        for (lane, acc) in lanes.iter_mut().enumerate() {
            let k = j + lane;
            let d = p3[k] - 3.0 * p2[k] + 3.0 * p1[k] - p0[k];
            *acc += d * d;
        }
        j += 4;
    }
    while j < span {
        let d = p3[j] - 3.0 * p2[j] + 3.0 * p1[j] - p0[j];
        lanes[0] += d * d;
        j += 1;
    }
    lanes.iter().sum()
}

/// Modified total variance at averaging factor m (needs 3m ≤ N = c.len());
/// meaningless once `stop` is raised.
pub fn mtot_var(c: &[f64], m: usize, stop: &Interrupt) -> f64 {
    let n = c.len();
    let l = 3 * m;
    let terms = n + 1 - l;
    let half = l / 2; // points in each half
    let gap = l.div_ceil(2) as f64; // distance between the halves' centres
    let inner = |i: usize, zp: &mut [f64], p: &mut [f64]| {
        let xs = &c[i..i + l];
        let x0 = xs[0];
        // Offsets cancel in D_j (they add a linear function to P): work on
        // x − x0, which keeps the digits of a phase far from zero.
        let mut first = Neumaier::new();
        let mut second = Neumaier::new();
        for k in 0..half {
            first.add(xs[k] - x0);
            second.add(xs[l - half + k] - x0);
        }
        let slope = (second.value() - first.value()) / half as f64 / gap;
        let mut run = 0.0;
        zp[0] = 0.0;
        for (k, &x) in xs.iter().enumerate() {
            run += (x - x0) - slope * k as f64;
            zp[k + 1] = run;
        }
        reflected_second_differences(zp, m, p)
    };
    let total = if m < REFLECTED_FROM {
        sum_over_subsequences(terms, m, 15 * m, inner, stop)
    } else {
        reflected_sum(|k| c[k], n, m, stop)
    };
    let mf = m as f64;
    total / (12.0 * mf.powi(5) * terms as f64)
}

/// Hadamard total variance at averaging factor m (needs 3m ≤ n = c.len() − 1);
/// at m = 1 the overlapping Hadamard variance, as Stable32 and allantools;
/// meaningless once `stop` is raised.
pub fn htot_var(c: &[f64], m: usize, stop: &Interrupt) -> f64 {
    if m == 1 {
        return DifferenceVariance::Hadamard { overlapping: true }
            .estimate(c, 1)
            .var;
    }
    let n = c.len() - 1;
    let l = 3 * m;
    let terms = n + 1 - l;
    let half = l / 2;
    let gap = l.div_ceil(2) as f64;
    let inner = |i: usize, zp: &mut [f64], p: &mut [f64]| {
        // Rate samples y_{i+k} = c_{i+k+1} − c_{i+k}; their prefix sums within the
        // subsequence are c_{i+k} − c_i.
        let base = c[i];
        let mean1 = (c[i + half] - base) / half as f64;
        let mean2 = (c[i + l] - c[i + l - half]) / half as f64;
        let slope = (mean2 - mean1) / gap;
        for k in 0..=l {
            let kf = k as f64;
            zp[k] = (c[i + k] - base) - slope * (kf * (kf - 1.0) / 2.0);
        }
        reflected_second_differences(zp, m, p)
    };
    let total = if m < REFLECTED_FROM {
        sum_over_subsequences(terms, m, 15 * m, inner, stop)
    } else {
        reflected_sum(|k| c[k + 1] - c[k], n, m, stop)
    };
    let mf = m as f64;
    total / (36.0 * mf.powi(3) * terms as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::phase::cumulative_phase;
    use crate::allan::test_signals::detrended_reflection;
    use crate::interrupt::NEVER;

    /// Direct transcription of the definitions (as allantools computes them),
    /// on phase values, without any of the tricks above.
    fn naive_mtot(x: &[f64], m: usize) -> f64 {
        let n = x.len();
        let l = 3 * m;
        let mut dev = 0.0;
        for i in 0..=n - l {
            let star = detrended_reflection(&x[i..i + l]);
            let mut s = 0.0;
            for j in 0..6 * m {
                let w = |a: usize| star[a..a + m].iter().sum::<f64>();
                let d = (w(j) - 2.0 * w(j + m) + w(j + 2 * m)) / m as f64;
                s += d * d;
            }
            dev += s / (6 * m) as f64;
        }
        dev / (2.0 * (m * m) as f64 * (n + 1 - l) as f64)
    }

    fn sample() -> Vec<f64> {
        let y: Vec<f64> = (0..300)
            .map(|k| ((k * 7919 + 13) % 101) as f64 - 50.0)
            .collect();
        cumulative_phase(y.into_iter()).unwrap()
    }

    #[test]
    fn mtot_matches_the_definition() {
        let c = sample();
        for m in [1, 2, 3, 7, 50, 100] {
            let (a, b) = (mtot_var(&c, m, &NEVER), naive_mtot(&c, m));
            assert!((a - b).abs() <= 1e-12 * b, "m {m}: {a} vs {b}");
        }
    }

    #[test]
    fn htot_is_mtot_of_the_rate_with_hadamard_scaling() {
        // HTOT on rate samples y equals MTOT's inner sums on y treated as phase,
        // scaled by 2m²·m²/(6·m²)... checked here through the definition directly.
        let c = sample();
        let y: Vec<f64> = c.windows(2).map(|w| w[1] - w[0]).collect();
        for m in [2, 3, 10, 99] {
            // naive_mtot(y) = Σ/(2 m² terms) with Σ the mean of (D/m)²; HTOT = Σ/(6 terms).
            let expected = naive_mtot(&y, m) * 2.0 * (m * m) as f64 / 6.0;
            let got = htot_var(&c, m, &NEVER);
            assert!((got - expected).abs() <= 1e-12 * expected, "m {m}");
        }
    }

    #[test]
    fn a_large_phase_offset_costs_no_digits() {
        let c = sample();
        let shifted: Vec<f64> = c.iter().map(|v| v + 1e9).collect();
        for m in [1, 5, 33] {
            let (a, b) = (mtot_var(&c, m, &NEVER), mtot_var(&shifted, m, &NEVER));
            assert!((a - b).abs() <= 1e-9 * a, "m {m}: {a} vs {b}");
        }
    }
}
