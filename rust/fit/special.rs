//! Digamma and trigamma, for the mean and variance of a log-χ² estimate.
//!
//! An Allan variance estimate with ν equivalent degrees of freedom is
//! σ̂² = σ²·χ²_ν/ν, so ln σ̂² = ln σ² + ln(χ²_ν/ν) with
//! E[ln(χ²_ν/ν)] = ψ(ν/2) − ln(ν/2) (≈ −1/ν) and var = ψ′(ν/2) (≈ 2/ν).
//! Both are evaluated by upward recurrence to x ≥ 16 and the asymptotic series
//! (Abramowitz & Stegun 6.3.18 and 6.4.12), accurate to ~1e-15 relative.

const SHIFT: f64 = 16.0;

/// ψ(x) − ln x for x > 0, without the cancellation of computing both separately
/// at large x (where the difference is ≈ −1/(2x)).
pub fn digamma_minus_log(x: f64) -> f64 {
    let mut x = x;
    let mut acc = 0.0;
    let start = x;
    while x < SHIFT {
        acc -= 1.0 / x;
        x += 1.0;
    }
    // ψ(start) − ln(start) = ψ(x) − ln x + ln(x/start) − Σ 1/(start + j)
    let inv = 1.0 / x;
    let inv2 = inv * inv;
    let series = -0.5 * inv
        - inv2
            * (1.0 / 12.0
                - inv2
                    * (1.0 / 120.0 - inv2 * (1.0 / 252.0 - inv2 * (1.0 / 240.0 - inv2 / 132.0))));
    series + acc + (x / start).ln()
}

/// Trigamma ψ′(x) for x > 0.
pub fn trigamma(x: f64) -> f64 {
    let mut x = x;
    let mut acc = 0.0;
    while x < SHIFT {
        acc += 1.0 / (x * x);
        x += 1.0;
    }
    let inv = 1.0 / x;
    let inv2 = inv * inv;
    acc + inv
        + inv2 * (0.5 + inv * (1.0 / 6.0 - inv2 * (1.0 / 30.0 - inv2 * (1.0 / 42.0 - inv2 / 30.0))))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        // ψ(1) = −γ, ψ(1/2) = −γ − 2 ln 2, ψ′(1) = π²/6, ψ′(1/2) = π²/2.
        let gamma = 0.577_215_664_901_532_9;
        assert!((digamma_minus_log(1.0) + gamma).abs() < 1e-14);
        let half = -gamma - 2.0 * std::f64::consts::LN_2 - 0.5f64.ln();
        assert!((digamma_minus_log(0.5) - half).abs() < 1e-14);
        let pi2 = std::f64::consts::PI * std::f64::consts::PI;
        assert!((trigamma(1.0) - pi2 / 6.0).abs() < 1e-14);
        assert!((trigamma(0.5) - pi2 / 2.0).abs() < 1e-13);
    }

    #[test]
    fn large_argument_limits() {
        for &x in &[1e3, 1e6, 1e9] {
            // ψ(x) − ln x = −1/(2x) − 1/(12x²) + …
            assert!(
                (digamma_minus_log(x) * 2.0 * x + 1.0 + 1.0 / (6.0 * x)).abs()
                    < 1e-12 + 1e-3 / (x * x)
            );
            assert!((trigamma(x) * x - 1.0).abs() < 1.0 / x);
        }
    }
}
