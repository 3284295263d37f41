//! The total family beyond TOTVAR: modified total (MTOT), Hadamard total (HTOT)
//! and Theo1, over the cumulative phase `c` (n + 1 points, in units of one
//! sample period; phase x = τ0·c, rate samples y_k = c_{k+1} − c_k).
//!
//! Definitions follow NIST SP 1065 (Riley 2008) eqs. 27, 29–30 and Howe's
//! papers as implemented by allantools and Stable32:
//!
//! - MTOT: for each of the N − 3m + 1 phase subsequences of 3m points, remove
//!   the linear trend given by the means of its first and last halves, extend it
//!   by uninverted even reflection to 9m points and average the 6m squared
//!   second differences of m-point means; σ² = Σ / (2 m² (N − 3m + 1)).
//! - HTOT: the same on the *rate* samples (n − 3m + 1 subsequences), with the
//!   Hadamard normalisation (divisor 6); at m = 1 the overlapping Hadamard
//!   variance is used, as Stable32 and allantools do.
//! - Theo1 (m even): σ² = Σ_i Σ_{δ<m/2} [(x_i − x_{i−δ+m/2}) + (x_{i+m} − x_{i+δ+m/2})]²
//!   / (m/2 − δ) / (0.75 (N − m) m²).
//!
//! Cost. Every subsequence is detrended and reflected on its own, so each tau
//! costs O(n·m): 15m operations per subsequence for MTOT/HTOT, m/2 for Theo1.
//! An O(n) formulation through global prefix sums of products (c_k·c_{k+l})
//! exists on paper, but it expands the squares into products of the raw phase,
//! which cancel catastrophically (for random-walk FM on 10⁶ points the terms are
//! ~10¹² times larger than their sum), and the reflections make anti-diagonal
//! sums (Σ_j c_{i+j}·c_{i+m−j}) that no one-dimensional prefix sum provides.
//! Here every subsequence works on offset-removed local values instead, which
//! keeps all digits; the subsequences of one tau are spread over threads.

use rayon::prelude::*;

use super::reflected::{reflected_sum, DIRECT_BELOW};
use super::sum::Neumaier;
use super::theo1;

/// Subsequences per parallel work item: large enough to amortise the scratch
/// buffer, small enough to balance two to sixteen threads.
const CHUNK_WORK: usize = 1 << 18;

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

/// Sum over `count` subsequences of `inner(i, zp, p)`, in parallel chunks with
/// per-chunk scratch buffers; chunk results are combined in order with
/// compensation so the answer does not depend on the thread count.
fn sum_over_subsequences<F>(count: usize, m: usize, per_item: usize, inner: F) -> f64
where
    F: Fn(usize, &mut [f64], &mut [f64]) -> f64 + Sync,
{
    let chunk = (CHUNK_WORK / per_item.max(1)).clamp(1, count.max(1));
    let chunks = count.div_ceil(chunk);
    let parts: Vec<f64> = (0..chunks)
        .into_par_iter()
        .map(|k| {
            let mut zp = vec![0.0; 3 * m + 1];
            let mut p = vec![0.0; 9 * m + 1];
            let mut acc = Neumaier::new();
            for i in k * chunk..((k + 1) * chunk).min(count) {
                acc.add(inner(i, &mut zp, &mut p));
            }
            acc.value()
        })
        .collect();
    let mut total = Neumaier::new();
    for v in parts {
        total.add(v);
    }
    total.value()
}

/// Modified total variance at averaging factor m (needs 3m ≤ N = c.len()).
pub fn mtot_var(c: &[f64], m: usize) -> f64 {
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
    let total = if m < DIRECT_BELOW {
        sum_over_subsequences(terms, m, 15 * m, inner)
    } else {
        reflected_sum(|k| c[k], n, m)
    };
    let mf = m as f64;
    total / (12.0 * mf.powi(5) * terms as f64)
}

/// Hadamard total variance at averaging factor m ≥ 2 (needs 3m ≤ n = c.len() − 1).
pub fn htot_var(c: &[f64], m: usize) -> f64 {
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
    let total = if m < DIRECT_BELOW {
        sum_over_subsequences(terms, m, 15 * m, inner)
    } else {
        reflected_sum(|k| c[k + 1] - c[k], n, m)
    };
    let mf = m as f64;
    total / (36.0 * mf.powi(3) * terms as f64)
}

/// Theo1 variance at even averaging factor m (needs m < N = c.len()).
pub fn theo1_var(c: &[f64], m: usize) -> f64 {
    let n = c.len();
    let h = m / 2;
    let outer = n - m;
    let weights: Vec<f64> = (1..=h).map(|k| 1.0 / k as f64).collect();
    // With k = m/2 − δ: term = (c_i + c_{i+m} − c_{i+k} − c_{i+m−k})² / k.
    let inner = |i: usize, _zp: &mut [f64], _p: &mut [f64]| {
        let ends = c[i] + c[i + m];
        let fwd = &c[i + 1..=i + h];
        let mut lanes = [0.0f64; 4];
        let mut k = 0;
        while k + 4 <= h {
            for (lane, acc) in lanes.iter_mut().enumerate() {
                let q = k + lane;
                let a = ends - fwd[q] - c[i + m - 1 - q];
                *acc += weights[q] * a * a;
            }
            k += 4;
        }
        while k < h {
            let a = ends - fwd[k] - c[i + m - 1 - k];
            lanes[0] += weights[k] * a * a;
            k += 1;
        }
        lanes.iter().sum::<f64>()
    };
    let total = if m < theo1::DIRECT_BELOW {
        // Scratch buffers are unused here: ask for the smallest.
        sum_over_subsequences(outer, 0, h.max(1), inner)
    } else {
        theo1::theo1_sum(c, m)
    };
    let mf = m as f64;
    total / (0.75 * outer as f64 * mf * mf)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::phase::cumulative_phase;
    use crate::allan::test_signals::naive_theo1;

    /// Direct transcription of the definitions (as allantools computes them),
    /// on phase values, without any of the tricks above.
    fn naive_mtot(x: &[f64], m: usize) -> f64 {
        let n = x.len();
        let l = 3 * m;
        let mut dev = 0.0;
        for i in 0..=n - l {
            let xs = &x[i..i + l];
            let h1 = l / 2;
            let h2 = l.div_ceil(2);
            let m1: f64 = xs[..h1].iter().sum::<f64>() / h1 as f64;
            let m2: f64 = xs[h2..].iter().sum::<f64>() / h1 as f64;
            let slope = (m2 - m1) / h2 as f64;
            let z: Vec<f64> = xs
                .iter()
                .enumerate()
                .map(|(k, v)| v - slope * k as f64)
                .collect();
            let mut star: Vec<f64> = z.iter().rev().copied().collect();
            star.extend(&z);
            star.extend(z.iter().rev());
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
            let (a, b) = (mtot_var(&c, m), naive_mtot(&c, m));
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
            let got = htot_var(&c, m);
            assert!((got - expected).abs() <= 1e-12 * expected, "m {m}");
        }
    }

    #[test]
    fn theo1_matches_the_definition() {
        let c = sample();
        for m in [2, 4, 10, 100, 300] {
            let (a, b) = (theo1_var(&c, m), naive_theo1(&c, m));
            assert!((a - b).abs() <= 1e-12 * b, "m {m}: {a} vs {b}");
        }
    }

    #[test]
    fn a_large_phase_offset_costs_no_digits() {
        let c = sample();
        let shifted: Vec<f64> = c.iter().map(|v| v + 1e9).collect();
        for m in [1, 5, 33] {
            let (a, b) = (mtot_var(&c, m), mtot_var(&shifted, m));
            assert!((a - b).abs() <= 1e-9 * a, "m {m}: {a} vs {b}");
        }
    }
}
