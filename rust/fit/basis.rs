//! Allan variance of each noise term per unit of its variance parameter.
//!
//! IEEE Std 952 terms (continuous-time forms, τ in seconds):
//! Q: 3/τ², N: 1/τ, B: 2 ln2/π, K: τ/3, R: τ²/2 (parameters Q², N², B², K², R²).
//!
//! First-order Gauss–Markov bias: the sampled process is the discrete AR1
//! xₜ = φxₜ₋₁ + wₜ with unit variance and φ = e^(−u), u = τ₀/τc (τ₀ = 1/fs).
//! With V(k) = var(x₁ + … + x_k) = k(1+φ)/(1−φ) − 2φ(1−φᵏ)/(1−φ)² and adjacent
//! cluster sums S₁, S₂ of m samples, var(S₂ − S₁) = 4V(m) − V(2m), so
//!
//! ```text
//! σ²(m) = [m(1 − φ²) − φ(1 − φᵐ)(3 − φᵐ)] / (m² (1 − φ)²)
//! ```
//!
//! (the discrete form of IEEE 952 Annex C's exponentially correlated term; for
//! m ≫ 1 and τc ≫ τ₀ the two agree). Near m·u → 0 the numerator cancels to
//! O((mu)³); there it is summed as its Taylor series in u, whose k-th term is
//! (−1)ᵏ/k!·[−m(2u)ᵏ − 3uᵏ + 4((m+1)u)ᵏ − ((2m+1)u)ᵏ] (the terms k ≤ 2 vanish).

/// Number of IEEE 952 terms: Q, N, B, K, R.
pub const IEEE_TERMS: usize = 5;

/// The IEEE 952 coefficients in the order of every array of the fit.
pub const IEEE_TERM_NAMES: [&str; IEEE_TERMS] = ["Q", "N", "B", "K", "R"];

/// (2 ln 2)/π: the Allan variance of flicker rate noise per unit B².
pub const FLICKER_FACTOR: f64 = 2.0 * std::f64::consts::LN_2 / std::f64::consts::PI;

/// Value of each IEEE basis function at `tau`.
pub fn ieee(tau: f64) -> [f64; IEEE_TERMS] {
    [
        3.0 / (tau * tau),
        1.0 / tau,
        FLICKER_FACTOR,
        tau / 3.0,
        tau * tau / 2.0,
    ]
}

/// Allan variance at cluster size `m` of a unit-variance AR1 with φ = e^(−u).
pub fn gauss_markov(m: f64, u: f64) -> f64 {
    let x = m * u;
    let d = -(-u).exp_m1(); // 1 − φ
    let numerator = if x < 0.5 {
        let mut sum = 0.0;
        let (mut p2, mut p1, mut pm1, mut p2m1) = (1.0, 1.0, 1.0, 1.0);
        let mut fact = 1.0;
        for k in 1..=40 {
            p2 *= 2.0 * u;
            p1 *= u;
            pm1 *= (m + 1.0) * u;
            p2m1 *= (2.0 * m + 1.0) * u;
            fact *= k as f64;
            if k < 3 {
                continue;
            }
            let c = -m * p2 - 3.0 * p1 + 4.0 * pm1 - p2m1;
            let term = if k % 2 == 0 { c / fact } else { -c / fact };
            sum += term;
            if term.abs() <= 1e-17 * sum.abs() {
                break;
            }
        }
        sum
    } else {
        let phi = (-u).exp();
        let e = -(-x).exp_m1(); // 1 − φᵐ
        m * d * (2.0 - d) - phi * e * (2.0 + e)
    };
    (numerator / (m * m * d * d)).max(0.0)
}

/// u = τ₀/τc of a Gauss–Markov term of correlation time `tau_c` at rate `fs`.
pub fn gm_rate(tau_c: f64, fs: f64) -> f64 {
    1.0 / (fs * tau_c)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// σ²(m) from the autocovariance γ(h) = φʰ, summed directly (DESIGN.md).
    fn direct(m: usize, phi: f64) -> f64 {
        let g = |h: usize| phi.powi(h as i32);
        let mf = m as f64;
        let mut s = mf;
        for h in 1..m {
            s += (2.0 * mf - 3.0 * h as f64) * g(h);
        }
        for h in m..2 * m {
            s -= (2.0 * mf - h as f64) * g(h);
        }
        s / (mf * mf)
    }

    #[test]
    fn matches_the_autocovariance_sum() {
        for &phi in &[0.0f64, 0.17, 0.5, 0.9, 0.99, 0.999] {
            let u = -f64::ln(phi.max(1e-300));
            for &m in &[1usize, 2, 3, 5, 10, 64, 300, 2000] {
                let want = direct(m, phi);
                let got = gauss_markov(m as f64, u);
                let tol = 1e-9 * want.abs().max(1e-12);
                assert!(
                    (got - want).abs() <= tol,
                    "phi {phi} m {m}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn limits_are_white_and_random_walk() {
        // m ≫ τc: white noise of density (1+φ)/(1−φ); m ≪ τc: slope +½.
        let u: f64 = 1e-3;
        let phi = (-u).exp();
        let m = 1e7;
        let white = (1.0 + phi) / (1.0 - phi) / m;
        assert!((gauss_markov(m, u) / white - 1.0).abs() < 1e-3);
        // For m·u ≪ 1: σ² ≈ u(2m² + 1)/(3m), the discrete random walk's form.
        for m in [1.0, 10.0, 40.0] {
            let want = 1e-6 * (2.0 * m * m + 1.0) / (3.0 * m);
            assert!((gauss_markov(m, 1e-6) / want - 1.0).abs() < 1e-4, "m {m}");
        }
    }

    #[test]
    fn continuous_across_the_series_switch() {
        for &u in &[1e-6, 1e-3, 0.1] {
            let m = 0.5 / u;
            let lo = gauss_markov(m * (1.0 - 1e-9), u);
            let hi = gauss_markov(m * (1.0 + 1e-9), u);
            assert!((lo / hi - 1.0).abs() < 1e-7, "u {u}: {lo} {hi}");
        }
    }
}
