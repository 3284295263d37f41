//! Power-law noise identification by the lag-1 autocorrelation method
//! (Riley & Greenhall, "Power law noise identification using the lag 1
//! autocorrelation", 18th EFTF, 2004), applied to phase data.
//!
//! The phase is decimated by the averaging factor, a quadratic is removed, and
//! the series is differenced until ρ = r1/(1 + r1) falls below 0.25 (or `dmax`
//! differences are done). Then α = 2 − round(2ρ) − 2d, the exponent of the
//! fractional-frequency PSD S_y(f) ∝ f^α.

// Small fixed-size linear algebra below indexes rows and columns as the formulas do.
#![allow(clippy::needless_range_loop)]

/// Fewer decimated points than this and the lag-1 estimate is too noisy to use.
pub const MIN_POINTS: usize = 30;

/// At most this many decimated points are used: the central stretch of the
/// record. The standard error of ρ is then below 0.005, far finer than the
/// rounding of 2ρ needs, and identification at short taus of long records costs
/// microseconds instead of a pass over the whole record per difference order.
pub const MAX_POINTS: usize = 1 << 16;

/// The identified integer α, or `None` when the decimated series is too short.
///
/// Records longer than [`MAX_POINTS`] decimated points are identified on their
/// central [`MAX_POINTS`]. Streams over `c` without copying it: the quadratic is fitted in one pass and
/// the residuals and their differences are evaluated on the fly.
pub fn identify_alpha(c: &[f64], m: usize, dmax: u32) -> Option<i32> {
    if m == 0 {
        return None;
    }
    let available = c.len().div_ceil(m);
    if available < MIN_POINTS {
        return None;
    }
    let len = available.min(MAX_POINTS);
    let first = (available - len) / 2;
    let x = |k: usize| c[(first + k) * m];
    let trend = QuadraticTrend::fit(len, x)?;
    let residual = |k: usize| x(k) - trend.at(k);
    for d in 0..=dmax {
        let count = len - d as usize;
        let value = |k: usize| difference(d, k, residual);
        let r1 = lag1_autocorrelation(count, value)?;
        let rho = r1 / (1.0 + r1);
        if rho < 0.25 || d >= dmax {
            return Some(2 - (2.0 * rho).round_ties_even() as i32 - 2 * d as i32);
        }
    }
    None
}

/// The d-th forward difference Σ_j (−1)^(d−j) C(d, j) r_{k+j} (d ≤ 3).
#[inline(always)]
fn difference(d: u32, k: usize, r: impl Fn(usize) -> f64) -> f64 {
    match d {
        0 => r(k),
        1 => r(k + 1) - r(k),
        2 => r(k + 2) - 2.0 * r(k + 1) + r(k),
        _ => r(k + 3) - 3.0 * r(k + 2) + 3.0 * r(k + 1) - r(k),
    }
}

/// r1 = Σ (x_k − x̄)(x_{k+1} − x̄) / Σ (x_k − x̄)². `None` for a constant series.
fn lag1_autocorrelation(count: usize, x: impl Fn(usize) -> f64) -> Option<f64> {
    if count < 2 {
        return None;
    }
    let mean = (0..count).map(&x).sum::<f64>() / count as f64;
    let mut num = 0.0;
    let mut den = 0.0;
    let mut previous = x(0) - mean;
    den += previous * previous;
    for k in 1..count {
        let a = x(k) - mean;
        den += a * a;
        num += previous * a;
        previous = a;
    }
    if den > 0.0 && den.is_finite() {
        Some(num / den)
    } else {
        None
    }
}

/// Least-squares quadratic in t scaled to [−1, 1], where the normal equations of
/// 1, t, t² are well conditioned for any length.
struct QuadraticTrend {
    coef: [f64; 3],
    scale: f64,
}

impl QuadraticTrend {
    fn fit(len: usize, x: impl Fn(usize) -> f64) -> Option<Self> {
        let scale = 2.0 / (len - 1) as f64;
        let mut gram = [[0.0f64; 3]; 3];
        let mut rhs = [0.0f64; 3];
        for k in 0..len {
            let t = k as f64 * scale - 1.0;
            let basis = [1.0, t, t * t];
            let v = x(k);
            for p in 0..3 {
                rhs[p] += basis[p] * v;
                for q in p..3 {
                    gram[p][q] += basis[p] * basis[q];
                }
            }
        }
        for p in 0..3 {
            for q in 0..p {
                gram[p][q] = gram[q][p];
            }
        }
        Some(QuadraticTrend {
            coef: solve3(gram, rhs)?,
            scale,
        })
    }

    #[inline(always)]
    fn at(&self, k: usize) -> f64 {
        let t = k as f64 * self.scale - 1.0;
        self.coef[0] + t * (self.coef[1] + t * self.coef[2])
    }
}

/// Gaussian elimination with partial pivoting on a 3×3 system.
fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let pivot = (col..3).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..3 {
            let f = a[row][col] / a[col][col];
            for k in col..3 {
                a[row][k] -= f * a[col][k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let tail: f64 = (row + 1..3).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - tail) / a[row][row];
    }
    Some(x)
}

/// Where a tau's series was too short to identify, use the median α of the (up
/// to) three nearest identified taus of the same channel; with none at all, white
/// FM (α = 0). The last identifiable taus rest on 30–60 points each, so one of
/// them is misidentified now and then; the median keeps a single outlier from
/// deciding the noise type (and so the EDF) of every longer tau.
pub fn fill_from_nearest(
    alpha: &mut [i32],
    known: &[bool],
    c: usize,
    channels: usize,
    taus: usize,
) {
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

    /// A small deterministic generator so the tests need no crate.
    fn white(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        let mut uniform = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| {
                // Box–Muller
                let (u1, u2) = (uniform().max(1e-300), uniform());
                (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
            })
            .collect()
    }

    fn cumsum(y: &[f64]) -> Vec<f64> {
        let mut c = vec![0.0];
        for v in y {
            c.push(c.last().unwrap() + v);
        }
        c
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
    fn white_frequency_noise_is_alpha_zero() {
        let c = cumsum(&white(4000, 7));
        assert_eq!(identify_alpha(&c, 1, 2), Some(0));
        assert_eq!(identify_alpha(&c, 10, 2), Some(0));
    }

    #[test]
    fn random_walk_frequency_is_alpha_minus_two() {
        let c = cumsum(&cumsum(&white(4000, 11)));
        assert_eq!(identify_alpha(&c, 1, 2), Some(-2));
    }

    #[test]
    fn white_phase_is_alpha_two() {
        let c = white(4000, 3);
        assert_eq!(identify_alpha(&c, 1, 2), Some(2));
    }

    #[test]
    fn quadratic_trend_is_removed_exactly() {
        let x = |k: usize| 3.0 + 0.5 * k as f64 - 0.01 * (k * k) as f64;
        let trend = QuadraticTrend::fit(100, x).unwrap();
        for k in [0, 17, 99] {
            assert!((trend.at(k) - x(k)).abs() < 1e-9);
        }
    }

    #[test]
    fn short_series_are_not_identified() {
        let c = cumsum(&white(100, 5));
        assert_eq!(identify_alpha(&c, 10, 2), None);
        assert_eq!(identify_alpha(&[0.0; 50], 1, 2), None);
    }
}
