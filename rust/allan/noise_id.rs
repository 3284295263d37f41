//! Power-law noise identification by the lag-1 autocorrelation method
//! (Riley & Greenhall, "Power law noise identification using the lag 1
//! autocorrelation", 18th EFTF, 2004), applied to phase data.
//!
//! The phase is decimated by the averaging factor, a quadratic is removed, and
//! the series is differenced until ρ = r1/(1 + r1) falls below 0.25 (or `dmax`
//! differences are done). Then α = 2 − round(2ρ) − 2d, the exponent of the
//! fractional-frequency PSD S_y(f) ∝ f^α.

/// Fewer decimated points than this and the lag-1 estimate is too noisy to use.
pub const MIN_POINTS: usize = 30;

/// The identified integer α, or `None` when the decimated series is too short.
pub fn identify_alpha(c: &[f64], m: usize, dmax: u32) -> Option<i32> {
    if m == 0 {
        return None;
    }
    let mut x: Vec<f64> = c.iter().step_by(m).copied().collect();
    if x.len() < MIN_POINTS {
        return None;
    }
    remove_quadratic(&mut x);
    let mut d = 0u32;
    loop {
        let r1 = lag1_autocorrelation(&x)?;
        let rho = r1 / (1.0 + r1);
        if rho < 0.25 || d >= dmax {
            return Some(2 - (2.0 * rho).round_ties_even() as i32 - 2 * d as i32);
        }
        for k in 0..x.len() - 1 {
            x[k] = x[k + 1] - x[k];
        }
        x.pop();
        d += 1;
        if x.len() < 2 {
            return None;
        }
    }
}

/// r1 = Σ (x_k − x̄)(x_{k+1} − x̄) / Σ (x_k − x̄)². `None` for a constant series.
fn lag1_autocorrelation(x: &[f64]) -> Option<f64> {
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let mut num = 0.0;
    let mut den = 0.0;
    for k in 0..x.len() {
        let a = x[k] - mean;
        den += a * a;
        if k + 1 < x.len() {
            num += a * (x[k + 1] - mean);
        }
    }
    if den > 0.0 && den.is_finite() {
        Some(num / den)
    } else {
        None
    }
}

/// Least-squares removal of 1, t, t² by projecting out an orthonormal basis built
/// with modified Gram–Schmidt on t scaled to [−1, 1] (well conditioned for any
/// length, unlike the normal equations of a raw polynomial fit).
fn remove_quadratic(x: &mut [f64]) {
    let n = x.len();
    let scale = if n > 1 { 2.0 / (n - 1) as f64 } else { 0.0 };
    let t = |k: usize| k as f64 * scale - 1.0;
    let mut basis: Vec<Vec<f64>> = Vec::with_capacity(3);
    for power in 0..3 {
        let mut v: Vec<f64> = (0..n).map(|k| t(k).powi(power)).collect();
        for q in &basis {
            let dot: f64 = q.iter().zip(&v).map(|(a, b)| a * b).sum();
            v.iter_mut().zip(q).for_each(|(vi, qi)| *vi -= dot * qi);
        }
        let norm = v.iter().map(|a| a * a).sum::<f64>().sqrt();
        if norm > 0.0 {
            v.iter_mut().for_each(|a| *a /= norm);
            basis.push(v);
        }
    }
    for q in &basis {
        let dot: f64 = q.iter().zip(x.iter()).map(|(a, b)| a * b).sum();
        x.iter_mut().zip(q).for_each(|(xi, qi)| *xi -= dot * qi);
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
    fn short_series_are_not_identified() {
        let c = cumsum(&white(100, 5));
        assert_eq!(identify_alpha(&c, 10, 2), None);
        assert_eq!(identify_alpha(&[0.0; 50], 1, 2), None);
    }
}
