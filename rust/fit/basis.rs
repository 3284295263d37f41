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

use rustfft::num_complex::Complex64;

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
        cancelling_numerator(m, u, Complex64::new(1.0, 0.0)).re
    } else {
        let phi = (-u).exp();
        let e = -(-x).exp_m1(); // 1 − φᵐ
        m * d * (2.0 - d) - phi * e * (2.0 + e)
    };
    (numerator / (m * m * d * d)).max(0.0)
}

/// Allan variance at cluster size `m`, τ = m·τ₀, of the rate of a bounded
/// motion: the increments xₖ = (θₖ − θₖ₋₁)/τ₀ of a unit-variance sampled AR1
/// θ with φ = e^(−u), u = τ₀/τc (a mount whose angle, or velocity, wanders and
/// comes back). The cluster mean of m rates is (θ_{k+m} − θₖ)/τ, so
///
/// ```text
/// σ²(τ) = (3 − 4φᵐ + φ²ᵐ)/τ²
/// ```
///
/// per unit of θ's variance: white rate noise of density 2/τc below τc (the
/// −½ slope), the quantization form 3/τ² beyond it (the −1 slope: the angle
/// stays bounded, so its rate averages away as 1/τ). Written with expm1, the
/// numerator −4(φᵐ − 1) + (φ²ᵐ − 1) loses at most a factor 2 to cancellation.
pub fn motion(tau: f64, m: f64, u: f64) -> f64 {
    let x = m * u;
    ((-2.0 * x).exp_m1() - 4.0 * (-x).exp_m1()) / (tau * tau)
}

/// Allan variance at cluster size `m` of a unit-variance sinusoid of random
/// phase at `nu` = f₀/fs cycles per sample (autocovariance γ(h) = cos 2πνh):
///
/// ```text
/// σ²(m) = 2 sin⁴(πνm) / (m² sin²(πν))
/// ```
///
/// (the cluster mean of sin(2πνn + ϕ) over m samples has amplitude
/// sin(πνm)/(m sin πν), the difference of two adjacent means 2 sin(πνm) times
/// that). The sampled form of IEEE 952 Annex C's sinusoidal term
/// Ω₀² sin⁴(πf₀τ)/(πf₀τ)² (variance Ω₀²/2 = 1 here), to which it tends for
/// f₀ ≪ fs; near fs/2 the two differ by a factor up to π²/4, and frequencies
/// above fs/2 alias onto fs − f₀.
pub fn sinusoid(m: f64, nu: f64) -> f64 {
    let s = (std::f64::consts::PI * nu * m).sin();
    let d = m * (std::f64::consts::PI * nu).sin();
    2.0 * s.powi(4) / (d * d)
}

/// Allan variance at cluster size `m` of a unit-variance damped oscillator (a
/// resonance, second-order Gauss–Markov process) with autocovariance
/// γ(h) = ρʰ cos θh, ρ = e^(−u) (u = τ₀/τr), θ = 2πf_r/fs.
///
/// σ²(m) is a sum over lags linear in γ with real coefficients, and
/// γ(h) = Re zʰ with z = ρe^(iθ) = e^(−w), w = u − iθ; so σ²(m) is the real part
/// of the first-order form [`gauss_markov`] continued to the complex rate w:
///
/// ```text
/// σ²(m) = Re [m(1 − z²) − z(1 − zᵐ)(3 − zᵐ)] / (m² (1 − z)²)
/// ```
///
/// The same cancellation as for the real AR1 appears when |m·w| is small (a
/// slow, barely oscillating resonance): there the numerator is summed as the
/// same Taylor series, whose terms carry w^k = |w|^k e^(ik arg w). It tends to
/// [`sinusoid`] as u → 0, to [`gauss_markov`] as θ → 0, and θ = π is the AR1
/// with φ = −ρ (a band peaked at fs/2).
pub fn resonance(m: f64, u: f64, theta: f64) -> f64 {
    resonance_parts(m, u, theta).0.max(0.0)
}

/// Allan variance at cluster size `m` of a resonance with a quadrature part:
/// autocovariance γ(h) = ρ^|h|·(cos θh + β sin θ|h|), the general stationary
/// second-order process with one zero (ARMA(2,1)), with β = `skew` · κ,
/// κ = [`quadrature_bound`]. A sensor's own second-order low-pass filter is one
/// (its output's autocovariance has β = cot ψ, tan ψ = (1 + ρ²)/(1 − ρ²)·tan θ;
/// a digital Butterworth filter, whose zeros sit at fs/2, has skew 1), which the
/// plain resonance (skew 0) draws only roughly. Since the lag sum is linear in γ
/// with real coefficients and sin θh = Im e^(iθh), σ²(m) is the real part of
/// [`resonance`]'s complex form plus β times its imaginary part.
///
/// Its spectrum, Re[(1 − iβ)(1 − z²)/|1 − z e^(−iω)|²], is non-negative at every
/// frequency exactly when |skew| ≤ 1; at skew 1 it touches zero at fs/2 (a
/// low-pass filter's zero), at −1 at zero frequency (the rate of a bounded
/// oscillation: no white noise at long τ). At θ = π the quadrature part vanishes.
pub fn skewed_resonance(m: f64, u: f64, theta: f64, skew: f64) -> f64 {
    let (cosine, sine) = resonance_parts(m, u, theta);
    let bound = quadrature_bound(u, theta);
    let quadrature = if bound.is_finite() {
        skew * bound * sine
    } else {
        0.0
    };
    (cosine + quadrature).max(0.0)
}

/// κ = sinh u / sin θ, the largest |β| of a [`skewed_resonance`] with a
/// non-negative spectrum (the numerator of the spectrum, a cosine polynomial of
/// degree one, touches zero at ω = 0 or π there). Infinite at θ = 0 or π, where
/// the quadrature part vanishes.
pub fn quadrature_bound(u: f64, theta: f64) -> f64 {
    let s = theta.sin().abs();
    if s < 1e-12 {
        f64::INFINITY
    } else {
        u.sinh() / s
    }
}

/// The Allan variances at cluster size `m` of the autocovariances ρ^|h| cos θh
/// and ρ^|h| sin θ|h|: the real and imaginary parts of
/// [m(1 − z²) − z(1 − zᵐ)(3 − zᵐ)] / (m² (1 − z)²) at z = e^(−u + iθ).
pub fn resonance_parts(m: f64, u: f64, theta: f64) -> (f64, f64) {
    let w = Complex64::new(u, -theta);
    let r = w.norm();
    let d = -expm1(-w); // 1 − z
    let numerator = if m * r < 0.5 {
        cancelling_numerator(m, r, Complex64::from_polar(1.0, w.arg()))
    } else {
        let z = (-w).exp();
        let e = -expm1(-w * m); // 1 − zᵐ
        d * (2.0 - d) * m - z * e * (2.0 + e)
    };
    let form = numerator / (d * d * (m * m));
    (form.re, form.im)
}

/// The numerator m(1 − z²) − z(1 − zᵐ)(3 − zᵐ) of the Gauss–Markov form at
/// z = e^(−w), w = r·e^(iα) (`phase` = e^(iα); 1 for the real AR1), where it
/// cancels to O((m|w|)³): summed as its Taylor series, whose k-th term is
/// (−1)ᵏ/k!·[−m·2ᵏ − 3 + 4(m+1)ᵏ − (2m+1)ᵏ]·rᵏ·e^(ikα) (the terms k ≤ 2 vanish).
fn cancelling_numerator(m: f64, r: f64, phase: Complex64) -> Complex64 {
    let mut sum = Complex64::new(0.0, 0.0);
    let mut turn = Complex64::new(1.0, 0.0);
    let (mut p2, mut p1, mut pm1, mut p2m1) = (1.0, 1.0, 1.0, 1.0);
    let mut fact = 1.0;
    for k in 1..=40 {
        p2 *= 2.0 * r;
        p1 *= r;
        pm1 *= (m + 1.0) * r;
        p2m1 *= (2.0 * m + 1.0) * r;
        fact *= k as f64;
        turn *= phase;
        if k < 3 {
            continue;
        }
        let c = -m * p2 - 3.0 * p1 + 4.0 * pm1 - p2m1;
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        let term = turn * (sign * c / fact);
        sum += term;
        if term.norm() <= 1e-17 * sum.norm() {
            break;
        }
    }
    sum
}

/// e^w − 1 without the cancellation of e^w − 1 for small |w|.
fn expm1(w: Complex64) -> Complex64 {
    let half = (0.5 * w.im).sin();
    Complex64::new(
        w.re.exp_m1() * w.im.cos() - 2.0 * half * half,
        w.re.exp() * w.im.sin(),
    )
}

/// (u, θ) of a resonance of frequency `f_r` (Hz) and damping time `tau_r` (s)
/// at rate `fs`: u = 1/(fs·τr), θ = 2πf_r/fs.
pub fn resonance_rates(f_r: f64, tau_r: f64, fs: f64) -> (f64, f64) {
    (1.0 / (fs * tau_r), 2.0 * std::f64::consts::PI * f_r / fs)
}

/// u = τ₀/τc of a Gauss–Markov term of correlation time `tau_c` at rate `fs`.
pub fn gm_rate(tau_c: f64, fs: f64) -> f64 {
    1.0 / (fs * tau_c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// σ²(m) from the autocovariance γ(h) = φʰ, summed directly (DESIGN.md).
    fn direct(m: usize, phi: f64) -> f64 {
        direct_from(m, |h| phi.powi(h as i32))
    }

    /// σ²(m) = var(S₂ − S₁)/(2m²) of adjacent m-sample sums, written as a sum
    /// over lags of any autocovariance γ with γ(0) = 1.
    fn direct_from(m: usize, g: impl Fn(usize) -> f64) -> f64 {
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
    fn sinusoid_matches_the_autocovariance_sum() {
        for &nu in &[1e-4, 0.013, 0.1, 0.2, 0.25, 0.37, 0.5] {
            let g = |h: usize| (2.0 * std::f64::consts::PI * nu * h as f64).cos();
            for &m in &[1usize, 2, 3, 5, 7, 10, 64, 300, 2000] {
                let want = direct_from(m, g);
                let got = sinusoid(m as f64, nu);
                // Absolute floor: the direct sum's rounding at the nulls.
                assert!(
                    (got - want).abs() <= 1e-9 * want.abs() + 1e-13,
                    "nu {nu} m {m}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn sinusoid_tends_to_the_ieee_form_and_has_nulls() {
        // IEEE 952 Annex C: Ω₀² sin⁴(πf₀τ)/(πf₀τ)² with Ω₀² = 2 (unit variance).
        let (fs, f0) = (1000.0, 0.7);
        for tau in [0.1, 0.5, 1.0, 3.3] {
            let x = std::f64::consts::PI * f0 * tau;
            let ieee = 2.0 * x.sin().powi(4) / (x * x);
            let got = sinusoid(tau * fs, f0 / fs);
            assert!((got / ieee - 1.0).abs() < 1e-5, "tau {tau}: {got} {ieee}");
        }
        // Zero at whole periods: a tone at fs/5 vanishes at m = 5, 10, …
        for m in [5.0, 10.0, 55.0] {
            assert!(sinusoid(m, 0.2) < 1e-25, "m {m}");
        }
    }

    #[test]
    fn resonance_matches_the_autocovariance_sum() {
        let two_pi = 2.0 * std::f64::consts::PI;
        for &rho in &[0.2f64, 0.5, 0.9, 0.99, 0.999, 0.99999] {
            for &nu in &[1e-5, 1e-3, 0.013, 0.1, 0.25, 0.37, 0.5] {
                let (u, theta) = (-rho.ln(), two_pi * nu);
                let g = |h: usize| rho.powi(h as i32) * (theta * h as f64).cos();
                for &m in &[1usize, 2, 3, 5, 7, 10, 64, 300, 2000] {
                    let want = direct_from(m, g);
                    let got = resonance(m as f64, u, theta);
                    assert!(
                        (got - want).abs() <= 1e-9 * want.abs() + 1e-13,
                        "rho {rho} nu {nu} m {m}: {got} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn skewed_resonance_matches_the_autocovariance_sum() {
        let two_pi = 2.0 * std::f64::consts::PI;
        for &rho in &[0.2f64, 0.5, 0.9, 0.99, 0.999] {
            for &nu in &[1e-3, 0.013, 0.1, 0.25, 0.37, 0.49] {
                let (u, theta) = (-rho.ln(), two_pi * nu);
                let bound = quadrature_bound(u, theta);
                for skew in [-1.0, -0.3, 0.5, 1.0] {
                    let beta = skew * bound;
                    let g = |h: usize| {
                        let h = h as f64;
                        rho.powf(h) * ((theta * h).cos() + beta * (theta * h).sin())
                    };
                    for &m in &[1usize, 2, 3, 5, 7, 10, 64, 300, 2000] {
                        let want = direct_from(m, g);
                        let got = skewed_resonance(m as f64, u, theta, skew);
                        let scale = resonance(m as f64, u, theta) + want.abs();
                        assert!(
                            (got - want).abs() <= 1e-9 * scale + 1e-13,
                            "rho {rho} nu {nu} skew {skew} m {m}: {got} vs {want}"
                        );
                    }
                }
            }
        }
    }

    /// Σₕ ρ^|h|(cos θh + β sin θ|h|)e^(−iωh), summed directly.
    fn skewed_spectrum(rho: f64, theta: f64, beta: f64, omega: f64) -> f64 {
        let mut s = 1.0;
        let mut h = 1.0;
        while rho.powf(h) > 1e-16 {
            let g = rho.powf(h) * ((theta * h).cos() + beta * (theta * h).sin());
            s += 2.0 * g * (omega * h).cos();
            h += 1.0;
        }
        s
    }

    #[test]
    fn the_quadrature_bound_is_where_the_spectrum_touches_zero() {
        for &(rho, theta) in &[(0.5f64, 0.4), (0.9, 1.0), (0.97, 2.0), (0.3, 2.9)] {
            let u = -rho.ln();
            let bound = quadrature_bound(u, theta);
            let lowest = |beta: f64| {
                (0..=2000)
                    .map(|k| skewed_spectrum(rho, theta, beta, PI * k as f64 / 2000.0))
                    .fold(f64::INFINITY, f64::min)
            };
            let peak = skewed_spectrum(rho, theta, 0.0, theta);
            // Skew 1 puts the zero at fs/2 (a low-pass filter's), −1 at 0.
            assert!(skewed_spectrum(rho, theta, bound, PI).abs() <= 1e-9 * peak);
            assert!(skewed_spectrum(rho, theta, -bound, 0.0).abs() <= 1e-9 * peak);
            for sign in [1.0, -1.0] {
                assert!(lowest(sign * bound) >= -1e-9 * peak, "{rho} {theta}");
                assert!(lowest(sign * bound) <= 1e-3 * peak, "{rho} {theta}");
                assert!(lowest(sign * 1.05 * bound) < 0.0, "{rho} {theta}");
            }
        }
    }

    #[test]
    fn resonance_tends_to_the_tone_and_to_gauss_markov() {
        for &m in &[1.0, 3.0, 10.0, 57.0, 400.0, 1e4] {
            for &nu in &[0.01, 0.17, 0.5] {
                let (tone, res) = (sinusoid(m, nu), resonance(m, 1e-12, 2.0 * PI * nu));
                // Absolute floor: the damping u = 1e-12 itself at the nulls.
                assert!(
                    (res - tone).abs() <= 1e-8 * tone + 1e-11,
                    "m {m}: {res} {tone}"
                );
            }
            for &u in &[1e-6, 1e-3, 0.1, 2.0] {
                let (gm, res) = (gauss_markov(m, u), resonance(m, u, 0.0));
                assert!((res / gm - 1.0).abs() < 1e-10, "m {m} u {u}: {res} {gm}");
            }
        }
        // θ = π: the AR1 with φ = −ρ, whose sum over lags alternates.
        let rho: f64 = 0.6;
        let want = direct_from(5, |h| (-rho).powi(h as i32));
        assert!((resonance(5.0, -rho.ln(), PI) / want - 1.0).abs() < 1e-12);
    }

    #[test]
    fn resonance_is_continuous_across_the_series_switch() {
        for &(u, theta) in &[(1e-6, 1e-6), (1e-3, 2e-3), (0.05, 0.1)] {
            let m = 0.5 / f64::hypot(u, theta);
            let lo = resonance(m * (1.0 - 1e-9), u, theta);
            let hi = resonance(m * (1.0 + 1e-9), u, theta);
            assert!((lo / hi - 1.0).abs() < 1e-7, "u {u}: {lo} {hi}");
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
    fn motion_matches_the_autocovariance_sum() {
        // Increments of a unit AR1 at τ₀ = 1: γ(0) = 2(1 − φ), γ(h ≥ 1) =
        // −φ^(h−1)(1 − φ)².
        for &phi in &[0.0f64, 0.3, 0.9, 0.99, 0.9999] {
            let u = -f64::ln(phi.max(1e-300));
            let g0 = 2.0 * (1.0 - phi);
            let g = |h: usize| -phi.powi(h as i32 - 1) * (1.0 - phi).powi(2) / g0;
            for &m in &[1usize, 2, 3, 10, 64, 300, 2000] {
                let want = g0 * direct_from(m, g);
                let got = motion(m as f64, m as f64, u);
                assert!(
                    (got - want).abs() <= 1e-9 * want.abs() + 1e-15,
                    "phi {phi} m {m}: {got} vs {want}"
                );
            }
        }
        // Limits: white of density 2/τc well below τc, 3/τ² well beyond.
        let (tau_c, fs) = (50.0, 100.0);
        let u = 1.0 / (fs * tau_c);
        let short = motion(0.1, 0.1 * fs, u) * 0.1;
        assert!((short / (2.0 / tau_c) - 1.0).abs() < 2e-3, "{short}");
        let long = motion(1e5, 1e5 * fs, u) * 1e10;
        assert!((long / 3.0 - 1.0).abs() < 1e-9, "{long}");
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
