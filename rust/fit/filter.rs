//! The sensor's output filter: white rate noise seen through a measured gain.
//!
//! A sensor low-pass filters (Butterworth, CIC decimator, FIR) its rate before it
//! samples it; no term of the IEEE model describes that, and a fit left alone
//! mimics the filter with a resonance, Gauss–Markov terms or tones. Given the
//! filter's power gain G(ν) = |H(ν)|² (ν in cycles per sample, G(0) = 1: the
//! white region's density is N²), the white term's Allan variance is
//! (N²/τ)·c(m) with
//!
//! ```text
//! c(m) = m ∫_{−½}^{½} G(ν) K_m(ν) dν = 1 + (4/m) ∫_0^½ (G(ν) − 1) sin⁴(πνm)/sin²(πν) dν
//! ```
//!
//! where K_m(ν) = 2 sin⁴(πνm)/(m² sin²πν) is the sampled Allan kernel
//! (`basis::sinusoid` per unit variance; ∫K_m = 1/m for white noise). c → 1 at
//! long τ, where only the low-frequency density counts.
//!
//! G is given on the uniform grid νₖ = k/(2(L − 1)), k = 0…L − 1, and read
//! linearly between its points. The integral is summed per grid segment: with
//! Simpson steps that resolve sin⁴(πνm) where a segment holds few of its periods,
//! and with sin⁴ replaced by its mean 3/8 where it holds many (the relative error
//! of that is of the order of 1/(periods in the segment), on a correction that is
//! itself O(1/m) there).

use crate::error::{CoreError, CoreResult};

/// Periods of sin⁴(πνm) in a grid segment above which it is averaged.
const AVERAGED_PERIODS: f64 = 4.0;

/// Simpson steps per period where sin⁴(πνm) is resolved.
const STEPS_PER_PERIOD: f64 = 16.0;

/// Simpson steps of an averaged segment (its integrand is smooth there).
const AVERAGED_STEPS: usize = 8;

/// A sensor's output filter: its power gain on a uniform frequency grid.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputFilter {
    gain: Vec<f64>,
}

impl OutputFilter {
    /// `gain`: G at νₖ = k/(2(L − 1)) cycles per sample (0 to fs/2), L ≥ 2, every
    /// value finite and ≥ 0, G(0) = 1.
    pub fn new(gain: Vec<f64>) -> CoreResult<OutputFilter> {
        if gain.len() < 2 {
            return Err(CoreError::InvalidArgument(format!(
                "filter must have at least 2 gains (0 Hz and fs/2); got {}",
                gain.len()
            )));
        }
        if let Some((k, g)) =
            (gain.iter().enumerate()).find(|(_, g)| !(g.is_finite() && **g >= 0.0))
        {
            return Err(CoreError::InvalidArgument(format!(
                "filter gains must be finite and >= 0; filter[{k}] = {g}"
            )));
        }
        if (gain[0] - 1.0).abs() > 1e-9 {
            return Err(CoreError::InvalidArgument(format!(
                "filter[0] (the gain at 0 Hz) must be 1: the white region's level is N²; got {}",
                gain[0]
            )));
        }
        Ok(OutputFilter { gain })
    }

    /// The gains, from 0 Hz to fs/2.
    pub fn gain(&self) -> &[f64] {
        &self.gain
    }

    fn spacing(&self) -> f64 {
        0.5 / (self.gain.len() - 1) as f64
    }

    /// G(ν) − 1, read linearly between the grid's points.
    fn excess(&self, nu: f64) -> f64 {
        let x = (nu / self.spacing()).clamp(0.0, (self.gain.len() - 1) as f64);
        let k = (x.floor() as usize).min(self.gain.len() - 2);
        let t = x - k as f64;
        self.gain[k] * (1.0 - t) + self.gain[k + 1] * t - 1.0
    }

    /// c(m): the white term's Allan variance through this filter over the one
    /// without, at cluster size `m` = τ·fs.
    pub fn white_factor(&self, m: f64) -> f64 {
        let h = self.spacing();
        let period = 1.0 / m;
        let resolved = |nu: f64| {
            let s = (std::f64::consts::PI * nu).sin();
            if s == 0.0 {
                // The limit ν → 0: sin⁴(πνm)/sin²(πν) → 0.
                return 0.0;
            }
            self.excess(nu) * (std::f64::consts::PI * nu * m).sin().powi(4) / (s * s)
        };
        let averaged = |nu: f64| {
            let s = (std::f64::consts::PI * nu).sin();
            self.excess(nu) * 0.375 / (s * s)
        };
        let mut integral = 0.0;
        for k in 0..self.gain.len() - 1 {
            if self.gain[k] == 1.0 && self.gain[k + 1] == 1.0 {
                continue;
            }
            let (a, b) = (k as f64 * h, (k + 1) as f64 * h);
            let periods = (b - a) / period;
            if periods <= AVERAGED_PERIODS {
                let steps = (periods * STEPS_PER_PERIOD).ceil().max(4.0) as usize;
                integral += simpson(resolved, a, b, steps);
            } else if k == 0 {
                // Near 0 Hz 1/sin² is steep: resolved over the first periods, then
                // averaged in ln ν.
                let edge = AVERAGED_PERIODS * period;
                integral += simpson(
                    resolved,
                    0.0,
                    edge,
                    (AVERAGED_PERIODS * STEPS_PER_PERIOD) as usize,
                );
                let in_log = |s: f64| averaged(s.exp()) * s.exp();
                integral += simpson(in_log, edge.ln(), b.ln(), 4 * AVERAGED_STEPS);
            } else {
                integral += simpson(averaged, a, b, AVERAGED_STEPS);
            }
        }
        1.0 + 4.0 / m * integral
    }
}

/// Composite Simpson's rule of `f` over [a, b] in `steps` (rounded up to even)
/// intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, steps: usize) -> f64 {
    let n = steps + steps % 2;
    let h = (b - a) / n as f64;
    let inner: f64 = (1..n)
        .map(|i| f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(a) + inner + f(b)) * h / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Allan variance at cluster size m of white noise through FIR `taps`, from
    /// its autocovariance in the time domain (independent of the integral):
    /// σ²(m) = (4V(m) − V(2m))/(2m²), V(k) = Σ_{|j|<k} (k − |j|)γ(j).
    fn fir_allan(taps: &[f64], m: usize) -> f64 {
        let gamma = |j: usize| -> f64 {
            (0..taps.len().saturating_sub(j))
                .map(|i| taps[i] * taps[i + j])
                .sum()
        };
        let v = |k: usize| -> f64 {
            gamma(0) * k as f64 + 2.0 * (1..k).map(|j| (k - j) as f64 * gamma(j)).sum::<f64>()
        };
        (4.0 * v(m) - v(2 * m)) / (2.0 * (m * m) as f64)
    }

    fn fir_gain(taps: &[f64], points: usize) -> Vec<f64> {
        let dc: f64 = taps.iter().sum();
        (0..points)
            .map(|k| {
                let nu = 0.5 * k as f64 / (points - 1) as f64;
                let (mut re, mut im) = (0.0, 0.0);
                for (i, t) in taps.iter().enumerate() {
                    let phase = 2.0 * std::f64::consts::PI * nu * i as f64;
                    re += t * phase.cos();
                    im -= t * phase.sin();
                }
                (re * re + im * im) / (dc * dc)
            })
            .collect()
    }

    #[test]
    fn white_factor_matches_the_time_domain_on_fir_filters() {
        let bartlett: Vec<f64> = (1..=8).chain((1..8).rev()).map(f64::from).collect();
        let boxcar = vec![1.0; 5];
        for taps in [bartlett, boxcar] {
            let filter = OutputFilter::new(fir_gain(&taps, 4097)).unwrap();
            let dc: f64 = taps.iter().sum();
            for m in [1usize, 2, 3, 5, 8, 13, 40, 100, 1000, 10_000] {
                let want = fir_allan(&taps, m) / (dc * dc / m as f64);
                let got = filter.white_factor(m as f64);
                assert!(
                    (got / want - 1.0).abs() < 2e-4,
                    "m {m}: {got} vs {want} ({taps:?})"
                );
            }
        }
    }

    #[test]
    fn no_filter_is_no_change() {
        let flat = OutputFilter::new(vec![1.0; 65]).unwrap();
        for m in [1.0, 7.0, 1e6] {
            assert_eq!(flat.white_factor(m), 1.0);
        }
    }

    #[test]
    fn bad_gains_are_errors() {
        assert!(OutputFilter::new(vec![1.0]).is_err());
        assert!(OutputFilter::new(vec![1.0, f64::NAN]).is_err());
        assert!(OutputFilter::new(vec![1.0, -0.1]).is_err());
        assert!(OutputFilter::new(vec![0.5, 0.1]).is_err());
    }
}
