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
//! linearly between its points. For such a G the integral is a finite sum,
//! evaluated exactly ([`PiecewiseLinear`]): the kernel m·K_m(ν) is a Fejér kernel
//! times sin²(πνm), a cosine sum of degree < 2m, so it only meets the Fourier
//! coefficients d_j of G − 1 (even about 0 and ½, on the circle ν ∈ [−½, ½]):
//!
//! ```text
//! c(m) − 1 = (A − B)/m,  A = Σ_{|j|<m} (m − |j|) d_j,  B = Σ_{0<j<2m} (m − |j − m|) d_j
//! ```
//!
//! (the time-domain Allan variance (4V(m) − V(2m))/(2m²), V(k) = Σ_{|j|<k} (k − |j|)γ_j,
//! of a process whose autocovariance is γ_j = d_j). The coefficients of the
//! piecewise-linear function are the DFT of its M = 2(L − 1) samples on the circle
//! times sinc²(πj/M), so d_j = w_{j mod M}/j² for j ≥ 1 with one table w of M
//! values; A and B come from running sums of d_j and j·d_j up to 2m, one pass
//! for all the cluster sizes asked at once.

use rustfft::num_complex::Complex64;

use crate::allan::sum::Neumaier;
use crate::error::{CoreError, CoreResult};
use crate::simd::FftPlans;

/// A sensor's output filter: its power gain on a uniform frequency grid.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputFilter {
    gain: Vec<f64>,
    /// G − 1, which is what the white term's Allan variance meets.
    excess: PiecewiseLinear,
    /// The relative standard uncertainty of the white level G was measured against
    /// ([`OutputFilter::with_level_std`]; 0: none).
    level_std: f64,
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
        let excess = PiecewiseLinear::new(&gain.iter().map(|g| g - 1.0).collect::<Vec<f64>>())?;
        Ok(OutputFilter {
            gain,
            excess,
            level_std: 0.0,
        })
    }

    /// The same filter, measured against a white level of relative standard
    /// uncertainty `std` (finite, ≥ 0): from its first point that is not 1 on, G is a
    /// spectrum over that level, so it scales as 1/level there, and the fit's
    /// covariance carries the level's uncertainty ([`OutputFilter::level_factors`]).
    pub fn with_level_std(mut self, std: f64) -> CoreResult<OutputFilter> {
        if !(std.is_finite() && std >= 0.0) {
            return Err(CoreError::InvalidArgument(format!(
                "the white level's relative uncertainty must be finite and >= 0; got {std}"
            )));
        }
        self.level_std = std;
        Ok(self)
    }

    /// The relative standard uncertainty of the white level G is measured against.
    pub fn level_std(&self) -> f64 {
        self.level_std
    }

    /// ∂c(m)/∂ln(level) at each cluster size of `ms`: G's measured part (from its
    /// first point that is not 1) scales as 1/level.
    pub fn level_factors(&self, ms: &[f64]) -> CoreResult<Vec<f64>> {
        let first = (self.gain.iter()).position(|&g| g != 1.0);
        let slope: Vec<f64> = (self.gain.iter().enumerate())
            .map(|(k, &g)| {
                if first.is_some_and(|f| k >= f) {
                    -g
                } else {
                    0.0
                }
            })
            .collect();
        Ok(PiecewiseLinear::new(&slope)?.kernel_sums(ms))
    }

    /// The gains, from 0 Hz to fs/2.
    pub fn gain(&self) -> &[f64] {
        &self.gain
    }

    /// c(m): the white term's Allan variance through this filter over the one
    /// without, at each cluster size `m` = τ·fs of `ms` ([`PiecewiseLinear::kernel_sums`]
    /// says how a fractional or sub-sample m is read).
    pub fn white_factors(&self, ms: &[f64]) -> Vec<f64> {
        (self.excess.kernel_sums(ms).into_iter())
            .map(|s| 1.0 + s)
            .collect()
    }
}

/// A function D(ν) on ν ∈ [0, ½] cycles per sample, given at νₖ = k/(2(L − 1))
/// and linear between its points, extended evenly about 0 and ½ (as a sampled
/// process's spectrum is), held as its Fourier coefficients on the circle.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseLinear {
    /// d₀ = ∫ D over the circle.
    mean: f64,
    /// w_r, r = 0…M − 1: d_j = w_{j mod M}/j² for j ≥ 1.
    weights: Vec<f64>,
}

impl PiecewiseLinear {
    /// `values`: D at the L ≥ 2 grid points, each finite.
    pub fn new(values: &[f64]) -> CoreResult<PiecewiseLinear> {
        let l = values.len();
        if l < 2 {
            return Err(CoreError::InvalidArgument(format!(
                "a density on the grid needs at least 2 values (0 Hz and fs/2); got {l}"
            )));
        }
        if let Some((k, v)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(CoreError::InvalidArgument(format!(
                "density values must be finite; density[{k}] = {v}"
            )));
        }
        let big = 2 * (l - 1);
        let mut circle: Vec<Complex64> = (values.iter())
            .chain(values[1..l - 1].iter().rev())
            .map(|&v| Complex64::new(v, 0.0))
            .collect();
        FftPlans::new().forward(big).process(&mut circle);
        // The DFT of an even sequence is real; ×sinc²(πj/M) = sin²(πr/M)·(M/(πj))².
        let scale = big as f64 / std::f64::consts::PI;
        let weights = (circle.iter().enumerate())
            .map(|(r, x)| {
                let s = (std::f64::consts::PI * r as f64 / big as f64).sin() * scale;
                x.re / big as f64 * s * s
            })
            .collect();
        Ok(PiecewiseLinear {
            mean: circle[0].re / big as f64,
            weights,
        })
    }

    /// S(m) = m ∫_{−½}^{½} D(ν) K_m(ν) dν, K_m(ν) = 2 sin⁴(πνm)/(m² sin²πν), at each
    /// cluster size of `ms`: the Allan variance at m of a process whose two-sided
    /// spectrum is D, times m (1 + S is c(m) for D = G − 1). Exact at whole m;
    /// between two whole sizes S is read linearly, and below one sample it is S(1)
    /// (an Allan variance exists at whole cluster sizes only).
    pub fn kernel_sums(&self, ms: &[f64]) -> Vec<f64> {
        let sizes: Vec<(u64, u64, f64)> = (ms.iter())
            .map(|&m| {
                let m = if m.is_nan() { 1.0 } else { m.max(1.0) };
                let lo = m.floor();
                (lo as u64, m.ceil() as u64, m - lo)
            })
            .collect();
        // The running sums P₀(n) = Σ_{1..n} d_j and P₁(n) = Σ_{1..n} j·d_j at every n
        // the sizes need, in one pass.
        let mut at: Vec<u64> = (sizes.iter())
            .flat_map(|&(lo, hi, _)| [lo - 1, lo, 2 * lo - 1, hi - 1, hi, 2 * hi - 1])
            .collect();
        at.sort_unstable();
        at.dedup();
        let period = self.weights.len();
        let (mut p0, mut p1) = (Neumaier::new(), Neumaier::new());
        let mut sums = Vec::with_capacity(at.len());
        let (mut j, mut r) = (0u64, 0usize);
        for &n in &at {
            while j < n {
                j += 1;
                r += 1;
                if r == period {
                    r = 0;
                }
                let (w, jf) = (self.weights[r], j as f64);
                p1.add(w / jf);
                p0.add(w / (jf * jf));
            }
            sums.push((p0.value(), p1.value()));
        }
        let sum_at = |n: u64| sums[at.binary_search(&n).unwrap_or(0)];
        let whole = |m: u64| -> f64 {
            let mf = m as f64;
            let (a0, a1) = sum_at(m - 1);
            let (b0, b1) = sum_at(m);
            let (c0, c1) = sum_at(2 * m - 1);
            let a = mf * self.mean + 2.0 * (mf * a0 - a1);
            let b = b1 + 2.0 * mf * (c0 - b0) - (c1 - b1);
            (a - b) / mf
        };
        (sizes.into_iter())
            .map(|(lo, hi, t)| {
                if t == 0.0 {
                    whole(lo)
                } else {
                    (1.0 - t) * whole(lo) + t * whole(hi)
                }
            })
            .collect()
    }
}

/// Allan variance at each of `taus` (s) of a process sampled at `fs` whose
/// one-sided density is `density` (units²/Hz at f_k = k·(fs/2)/(L − 1), linear
/// between its points, any sign: a difference of two spectra): S(m)/(2τ).
pub fn density_allan(density: &[f64], taus: &[f64], fs: f64) -> CoreResult<Vec<f64>> {
    let spectrum = PiecewiseLinear::new(density)?;
    let ms: Vec<f64> = taus.iter().map(|t| t * fs).collect();
    Ok((spectrum.kernel_sums(&ms).into_iter().zip(taus))
        .map(|(s, t)| s / (2.0 * t))
        .collect())
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
                let got = filter.white_factors(&[m as f64])[0];
                assert!(
                    // what is left is the linear reading of |H|² between 4097 points
                    (got / want - 1.0).abs() < 1e-5,
                    "m {m}: {got} vs {want} ({taps:?})"
                );
            }
        }
    }

    /// S(m) from Fourier coefficients integrated segment by segment in closed form
    /// (∫ (α + βν) cos 2πjν dν), summed directly: no FFT, no sinc², no running sums.
    fn direct_kernel_sum(values: &[f64], m: usize) -> f64 {
        let h = 0.5 / (values.len() - 1) as f64;
        let coefficient = |j: usize| -> f64 {
            let k = 2.0 * std::f64::consts::PI * j as f64;
            let mut total = 0.0;
            for s in 0..values.len() - 1 {
                let (a, b) = (s as f64 * h, (s + 1) as f64 * h);
                let slope = (values[s + 1] - values[s]) / h;
                let at = |x: f64| values[s] + slope * (x - a);
                total += if j == 0 {
                    (values[s] + values[s + 1]) * h / 2.0
                } else {
                    // ∫ f cos kx = [f sin kx / k + f' cos kx / k²]
                    let end = |x: f64| at(x) * (k * x).sin() / k + slope * (k * x).cos() / (k * k);
                    end(b) - end(a)
                };
            }
            2.0 * total // even about 0: the circle's other half
        };
        let d: Vec<f64> = (0..2 * m).map(coefficient).collect();
        let a: f64 = m as f64 * d[0] + 2.0 * (1..m).map(|j| (m - j) as f64 * d[j]).sum::<f64>();
        let b: f64 = (1..2 * m)
            .map(|j| (m as f64 - (j as f64 - m as f64).abs()) * d[j])
            .sum();
        (a - b) / m as f64
    }

    #[test]
    fn kernel_sums_are_the_coefficients_summed_directly() {
        let shapes: [Vec<f64>; 3] = [
            (0..33).map(|k| (-(k as f64) / 6.0).exp() - 1.0).collect(),
            (0..17).map(|k| if k < 8 { 0.0 } else { -0.5 }).collect(),
            (0..9).map(|k| 0.25 * k as f64).collect(),
        ];
        for values in shapes {
            let spectrum = PiecewiseLinear::new(&values).unwrap();
            let ms = [1usize, 2, 3, 7, 16, 31, 64, 100, 257];
            let got = spectrum.kernel_sums(&ms.map(|m| m as f64));
            for (m, got) in ms.iter().zip(got) {
                let want = direct_kernel_sum(&values, *m);
                assert!(
                    (got - want).abs() < 1e-12 * (1.0 + want.abs()),
                    "m {m}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn between_whole_sizes_the_sum_is_read_linearly() {
        let values: Vec<f64> = (0..65).map(|k| -(k as f64 / 64.0).powi(2)).collect();
        let spectrum = PiecewiseLinear::new(&values).unwrap();
        let s = spectrum.kernel_sums(&[3.0, 4.0, 3.25, 0.5, 1.0]);
        assert!((s[2] - (0.75 * s[0] + 0.25 * s[1])).abs() < 1e-15, "{s:?}");
        assert_eq!(s[3], s[4]);
        // the order of the sizes asked does not matter
        assert_eq!(spectrum.kernel_sums(&[4.0, 3.0]), [s[1], s[0]]);
    }

    #[test]
    fn density_allan_of_white_noise_is_its_level_over_twice_tau() {
        // A one-sided density h0 is white noise of Allan variance h0/(2τ).
        let fs = 50.0;
        let got = density_allan(&[3.0; 129], &[0.02, 0.5, 40.0], fs).unwrap();
        for (g, t) in got.iter().zip([0.02, 0.5, 40.0]) {
            assert!((g / (3.0 / (2.0 * t)) - 1.0).abs() < 1e-12, "{got:?}");
        }
    }

    #[test]
    fn the_white_levels_uncertainty_is_the_fits_slope_in_it() {
        // N + B + K through a 4-tap moving average, fitted exactly; the covariance a
        // level uncertainty u adds to the white variance is u²·(dN²/dε)², with the
        // slope from refits whose measured gain is scaled by e^(∓δ).
        use crate::fit::{fit_noise, Kind, Options, Term};
        let fs = 100.0;
        let gain: Vec<f64> = (0..257)
            .map(|k| {
                let s = (std::f64::consts::PI * 0.5 * k as f64 / 256.0).sin();
                if s == 0.0 {
                    1.0
                } else {
                    ((4.0 * std::f64::consts::PI * 0.5 * k as f64 / 256.0).sin() / (4.0 * s))
                        .powi(2)
                }
            })
            .collect();
        let taus: Vec<f64> = (0..40).map(|i| 0.01 * 1.25f64.powi(i)).collect();
        let truth = [
            Term::White { variance: 4e-6 },
            Term::Flicker { variance: 1e-8 },
            Term::RandomWalk { variance: 1e-10 },
        ];
        let filter = OutputFilter::new(gain.clone()).unwrap();
        let var: Vec<f64> = (crate::fit::allan_terms(&taus, fs, &truth, Some(&filter)).iter())
            .map(|r| r.iter().sum())
            .collect();
        let edf: Vec<f64> = taus.iter().map(|t| 1e5 / (t * fs)).collect();
        let opts = Options::exactly(&[(Kind::White, 1), (Kind::Flicker, 1), (Kind::RandomWalk, 1)]);
        let white = |f: &OutputFilter| {
            let fit = fit_noise(&taus, &var, &edf, fs, &opts, Some(f)).unwrap();
            let k = fit
                .terms
                .iter()
                .position(|t| t.kind() == Kind::White)
                .unwrap();
            (fit.terms[k].variance(), fit.cov[k][k])
        };
        let delta = 1e-4;
        let scaled = |e: f64| {
            let g = gain
                .iter()
                .enumerate()
                .map(|(k, g)| if k == 0 { 1.0 } else { g * (-e).exp() });
            OutputFilter::new(g.collect()).unwrap()
        };
        let slope = (white(&scaled(delta)).0 - white(&scaled(-delta)).0) / (2.0 * delta);
        let u = 0.01;
        let (_, plain) = white(&filter);
        let (_, with) = white(&filter.clone().with_level_std(u).unwrap());
        let predicted = ((with - plain).max(0.0)).sqrt() / u;
        assert!(slope.abs() > 1e-7, "{slope}");
        assert!(
            (predicted / slope.abs() - 1.0).abs() < 1e-3,
            "{predicted} vs {slope}"
        );
        assert!(OutputFilter::new(gain)
            .unwrap()
            .with_level_std(f64::NAN)
            .is_err());
    }

    #[test]
    fn no_filter_is_no_change() {
        let flat = OutputFilter::new(vec![1.0; 65]).unwrap();
        for m in [1.0, 7.0, 1e6] {
            assert_eq!(flat.white_factors(&[m]), [1.0]);
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
