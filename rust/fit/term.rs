//! One term of the noise model, typed: each kind owns its parameters, its Allan
//! variance, its block of the parameter covariance and what it adds to the
//! datasheet's N and K.
//!
//! Adding a kind of term: a variant here (its parameters, [`Term::unit_variance`],
//! [`Term::coordinates`] and their derivatives, its datasheet share), its
//! candidates in `search`, and its Python class in `python/imunoise/noise/terms.py`.

use super::basis::{self, IEEE_TERMS};
use crate::error::{CoreError, CoreResult};

/// The kinds of term, in the order a model lists them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    Quantization,
    White,
    Flicker,
    RandomWalk,
    Ramp,
    GaussMarkov,
    Tone,
    Resonance,
    Motion,
}

impl Kind {
    /// Every kind, in the order a model lists them.
    pub const ALL: [Kind; 9] = [
        Kind::Quantization,
        Kind::White,
        Kind::Flicker,
        Kind::RandomWalk,
        Kind::Ramp,
        Kind::GaussMarkov,
        Kind::Tone,
        Kind::Resonance,
        Kind::Motion,
    ];

    /// The IEEE 952 kinds in the order of their coefficients Q, N, B, K, R.
    pub const IEEE: [Kind; IEEE_TERMS] = [
        Kind::Quantization,
        Kind::White,
        Kind::Flicker,
        Kind::RandomWalk,
        Kind::Ramp,
    ];

    /// Most terms of this kind a model may have.
    pub fn most(self) -> usize {
        match self {
            Kind::GaussMarkov => super::MAX_GM,
            Kind::Tone => super::MAX_TONES,
            _ => 1,
        }
    }

    /// The kind's name, as Python spells its class in snake case.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Quantization => "quantization",
            Kind::White => "white",
            Kind::Flicker => "flicker",
            Kind::RandomWalk => "random_walk",
            Kind::Ramp => "ramp",
            Kind::GaussMarkov => "gauss_markov",
            Kind::Tone => "tone",
            Kind::Resonance => "resonance",
            Kind::Motion => "motion",
        }
    }

    /// Names of the parameters, as [`Term::parameters`] lists them.
    pub fn parameter_names(self) -> &'static [&'static str] {
        match self {
            Kind::Quantization | Kind::White | Kind::Flicker | Kind::RandomWalk | Kind::Ramp => {
                &["variance"]
            }
            Kind::GaussMarkov | Kind::Motion => &["variance", "tau_c"],
            Kind::Tone => &["variance", "freq"],
            Kind::Resonance => &["variance", "freq", "tau", "skew"],
        }
    }

    /// Names of the covariance coordinates, as [`Term::coordinates`] lists them:
    /// variances as they are, times and frequencies by their logarithm (the fit's
    /// own coordinates: a correlation time's uncertainty is relative).
    pub fn coordinate_names(self) -> &'static [&'static str] {
        match self {
            Kind::Quantization | Kind::White | Kind::Flicker | Kind::RandomWalk | Kind::Ramp => {
                &["variance"]
            }
            Kind::GaussMarkov | Kind::Motion => &["variance", "ln_tau_c"],
            Kind::Tone => &["variance", "ln_freq"],
            Kind::Resonance => &["variance", "ln_freq", "ln_tau", "skew"],
        }
    }

    /// The kind named `name` ([`Kind::name`]).
    pub fn from_name(name: &str) -> CoreResult<Kind> {
        Kind::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| {
                let names: Vec<&str> = Kind::ALL.iter().map(|k| k.name()).collect();
                CoreError::InvalidArgument(format!(
                    "term kind must be one of {}; got {name:?}",
                    names.join(", ")
                ))
            })
    }
}

/// One fitted term of the model. Every variance is the term's variance
/// parameter in (rate)² units of its kind: Q², N², B², K², R² for the IEEE
/// terms; q² of a Gauss–Markov bias; s² = A²/2 of a tone of amplitude A; r² of a
/// resonance; σθ² of a bounded motion's angle (or velocity).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Term {
    /// Quantization noise, Allan variance 3Q²/τ².
    Quantization { variance: f64 },
    /// White rate noise, N²/τ (through the output filter, if the model has one).
    White { variance: f64 },
    /// Flicker (bias instability), (2 ln 2/π)·B².
    Flicker { variance: f64 },
    /// Rate random walk, K²τ/3.
    RandomWalk { variance: f64 },
    /// Rate ramp, R²τ²/2.
    Ramp { variance: f64 },
    /// First-order Gauss–Markov bias of correlation time τc (s).
    GaussMarkov { variance: f64, tau_c: f64 },
    /// A sinusoid of random phase at `freq` (Hz).
    Tone { variance: f64, freq: f64 },
    /// A damped oscillator at `freq` (Hz), damping time `tau` (s), quadrature
    /// part `skew` in [−1, 1] (`basis::skewed_resonance`).
    Resonance {
        variance: f64,
        freq: f64,
        tau: f64,
        skew: f64,
    },
    /// A bounded motion of the mount: its angle wanders as a Gauss–Markov
    /// process of correlation time τc (s) and comes back (`basis::motion`).
    Motion { variance: f64, tau_c: f64 },
}

/// Relative step of the central differences in the logarithm of a time.
const LOG_STEP: f64 = 1e-4;

impl Term {
    /// The IEEE term of coefficient index `j` (Q, N, B, K, R) and `variance`.
    pub fn ieee(j: usize, variance: f64) -> Term {
        match Kind::IEEE[j] {
            Kind::Quantization => Term::Quantization { variance },
            Kind::White => Term::White { variance },
            Kind::Flicker => Term::Flicker { variance },
            Kind::RandomWalk => Term::RandomWalk { variance },
            _ => Term::Ramp { variance },
        }
    }

    pub fn kind(&self) -> Kind {
        match self {
            Term::Quantization { .. } => Kind::Quantization,
            Term::White { .. } => Kind::White,
            Term::Flicker { .. } => Kind::Flicker,
            Term::RandomWalk { .. } => Kind::RandomWalk,
            Term::Ramp { .. } => Kind::Ramp,
            Term::GaussMarkov { .. } => Kind::GaussMarkov,
            Term::Tone { .. } => Kind::Tone,
            Term::Resonance { .. } => Kind::Resonance,
            Term::Motion { .. } => Kind::Motion,
        }
    }

    /// The term's variance parameter.
    pub fn variance(&self) -> f64 {
        match *self {
            Term::Quantization { variance }
            | Term::White { variance }
            | Term::Flicker { variance }
            | Term::RandomWalk { variance }
            | Term::Ramp { variance }
            | Term::GaussMarkov { variance, .. }
            | Term::Tone { variance, .. }
            | Term::Resonance { variance, .. }
            | Term::Motion { variance, .. } => variance,
        }
    }

    /// The same term with variance `variance`.
    pub fn with_variance(self, variance: f64) -> Term {
        match self {
            Term::Quantization { .. } => Term::Quantization { variance },
            Term::White { .. } => Term::White { variance },
            Term::Flicker { .. } => Term::Flicker { variance },
            Term::RandomWalk { .. } => Term::RandomWalk { variance },
            Term::Ramp { .. } => Term::Ramp { variance },
            Term::GaussMarkov { tau_c, .. } => Term::GaussMarkov { variance, tau_c },
            Term::Tone { freq, .. } => Term::Tone { variance, freq },
            Term::Resonance {
                freq, tau, skew, ..
            } => Term::Resonance {
                variance,
                freq,
                tau,
                skew,
            },
            Term::Motion { tau_c, .. } => Term::Motion { variance, tau_c },
        }
    }

    /// The parameters, in the order of [`Kind::parameter_names`].
    pub fn parameters(&self) -> Vec<f64> {
        match *self {
            Term::GaussMarkov { variance, tau_c } | Term::Motion { variance, tau_c } => {
                vec![variance, tau_c]
            }
            Term::Tone { variance, freq } => vec![variance, freq],
            Term::Resonance {
                variance,
                freq,
                tau,
                skew,
            } => vec![variance, freq, tau, skew],
            other => vec![other.variance()],
        }
    }

    /// The term of kind `kind` with `parameters` ([`Kind::parameter_names`]),
    /// checked: variance finite and ≥ 0, times and frequencies finite and > 0,
    /// skew in [−1, 1].
    pub fn new(kind: Kind, parameters: &[f64]) -> CoreResult<Term> {
        let names = kind.parameter_names();
        if parameters.len() != names.len() {
            return Err(CoreError::InvalidArgument(format!(
                "a {} term has {} parameters ({}); got {}",
                kind.name(),
                names.len(),
                names.join(", "),
                parameters.len()
            )));
        }
        for (name, &p) in names.iter().zip(parameters) {
            let ok = match *name {
                "variance" => p.is_finite() && p >= 0.0,
                "skew" => (-1.0..=1.0).contains(&p),
                _ => p.is_finite() && p > 0.0,
            };
            if !ok {
                let bound = match *name {
                    "variance" => "finite and >= 0",
                    "skew" => "in [-1, 1]",
                    _ => "finite and > 0",
                };
                return Err(CoreError::InvalidArgument(format!(
                    "{} {name} must be {bound}; got {p}",
                    kind.name()
                )));
            }
        }
        let p = parameters;
        Ok(match kind {
            Kind::GaussMarkov => Term::GaussMarkov {
                variance: p[0],
                tau_c: p[1],
            },
            Kind::Motion => Term::Motion {
                variance: p[0],
                tau_c: p[1],
            },
            Kind::Tone => Term::Tone {
                variance: p[0],
                freq: p[1],
            },
            Kind::Resonance => Term::Resonance {
                variance: p[0],
                freq: p[1],
                tau: p[2],
                skew: p[3],
            },
            ieee => Term::ieee(
                Kind::IEEE.iter().position(|k| *k == ieee).unwrap_or(0),
                p[0],
            ),
        })
    }

    /// Allan variance per unit variance at τ = `tau` (cluster size `m` = τ·fs);
    /// `white` is the output filter's factor at this τ (1 without one).
    pub fn unit_variance(&self, tau: f64, m: f64, fs: f64, white: f64) -> f64 {
        match *self {
            Term::Quantization { .. } => basis::ieee(tau)[0],
            Term::White { .. } => basis::ieee(tau)[1] * white,
            Term::Flicker { .. } => basis::ieee(tau)[2],
            Term::RandomWalk { .. } => basis::ieee(tau)[3],
            Term::Ramp { .. } => basis::ieee(tau)[4],
            Term::GaussMarkov { tau_c, .. } => basis::gauss_markov(m, basis::gm_rate(tau_c, fs)),
            Term::Tone { freq, .. } => basis::sinusoid(m, freq / fs),
            Term::Resonance {
                freq,
                tau: tr,
                skew,
                ..
            } => {
                let (u, theta) = basis::resonance_rates(freq, tr, fs);
                basis::skewed_resonance(m, u, theta, skew)
            }
            Term::Motion { tau_c, .. } => basis::motion(tau, m, basis::gm_rate(tau_c, fs)),
        }
    }

    /// The term's Allan variance at τ = `tau` (see [`Term::unit_variance`]).
    pub fn allan_variance(&self, tau: f64, m: f64, fs: f64, white: f64) -> f64 {
        self.variance() * self.unit_variance(tau, m, fs, white)
    }

    /// Which covariance coordinates ([`Kind::coordinate_names`]) are free: a
    /// resonance at fs/2 has no free frequency (its curve is even in f_r − fs/2
    /// there), and a skew of 0 (the plain resonance) or on its bound ±1 is none.
    pub fn free(&self, fs: f64) -> Vec<bool> {
        match *self {
            Term::Resonance { freq, skew, .. } => vec![
                true,
                freq < 0.5 * fs * (1.0 - 1e-9),
                true,
                skew != 0.0 && skew.abs() < 1.0 - 1e-9,
            ],
            other => vec![true; other.kind().coordinate_names().len()],
        }
    }

    /// ∂σ²(τ)/∂ each covariance coordinate at τ = `tau`, by the same rule for
    /// every term: exact in the variance (and the skew, in which the curve is
    /// linear), central differences of step [`LOG_STEP`] in a logarithm.
    pub fn gradient(&self, tau: f64, m: f64, fs: f64, white: f64) -> Vec<f64> {
        let h = LOG_STEP;
        let (up, down) = (h.exp(), (-h).exp());
        let at = |t: Term| t.allan_variance(tau, m, fs, white);
        let unit = self.unit_variance(tau, m, fs, white);
        match *self {
            Term::GaussMarkov { variance, tau_c } => vec![
                unit,
                (at(Term::GaussMarkov {
                    variance,
                    tau_c: tau_c * up,
                }) - at(Term::GaussMarkov {
                    variance,
                    tau_c: tau_c * down,
                })) / (2.0 * h),
            ],
            Term::Motion { variance, tau_c } => vec![
                unit,
                (at(Term::Motion {
                    variance,
                    tau_c: tau_c * up,
                }) - at(Term::Motion {
                    variance,
                    tau_c: tau_c * down,
                })) / (2.0 * h),
            ],
            Term::Tone { variance, freq } => vec![
                unit,
                (at(Term::Tone {
                    variance,
                    freq: freq * up,
                }) - at(Term::Tone {
                    variance,
                    freq: freq * down,
                })) / (2.0 * h),
            ],
            Term::Resonance {
                variance,
                freq,
                tau: tr,
                skew,
            } => {
                let shifted = |f: f64, t: f64| {
                    at(Term::Resonance {
                        variance,
                        freq: f,
                        tau: t,
                        skew,
                    })
                };
                let (u, theta) = basis::resonance_rates(freq, tr, fs);
                let bound = basis::quadrature_bound(u, theta);
                vec![
                    unit,
                    (shifted(freq * up, tr) - shifted(freq * down, tr)) / (2.0 * h),
                    (shifted(freq, tr * up) - shifted(freq, tr * down)) / (2.0 * h),
                    // Linear in the skew: r²·κ times the quadrature form.
                    variance * bound * basis::resonance_parts(m, u, theta).1,
                ]
            }
            _ => vec![unit],
        }
    }
}

/// τ/τc where a first-order Gauss–Markov term's Allan variance peaks (IEEE 952
/// Annex C): its hump. Below it the term rises like a random walk.
pub const GM_PEAK: f64 = 1.8926;

impl Term {
    /// The coordinates of [`Kind::coordinate_names`]: the variance, the
    /// logarithm of each time and frequency, the skew.
    pub fn coordinates(&self) -> Vec<f64> {
        (self
            .parameters()
            .into_iter()
            .zip(self.kind().coordinate_names()))
        .map(|(p, name)| if name.starts_with("ln_") { p.ln() } else { p })
        .collect()
    }

    /// The term of kind `kind` at `coordinates` ([`Term::coordinates`]).
    pub fn from_coordinates(kind: Kind, coordinates: &[f64]) -> CoreResult<Term> {
        let parameters: Vec<f64> = (coordinates.iter().zip(kind.coordinate_names()))
            .map(|(&x, name)| if name.starts_with("ln_") { x.exp() } else { x })
            .collect();
        Term::new(kind, &parameters)
    }

    /// What the term adds to the datasheet's N² (the white level a reader draws
    /// through τ = 1 s): the white term itself; the −½ asymptote of a Gauss–Markov
    /// term whose hump (τ ≈ 1.89 τc) lies before τ = 1 s (past its hump it falls
    /// toward that asymptote; before it, it rises like a walk and is a bump, no
    /// part of a −½ line); and that of a resonance damped faster than 1 s (a
    /// sensor's filter passes its input's white noise). Nothing for the rest.
    pub fn white_share(&self, fs: f64) -> f64 {
        match *self {
            Term::White { variance } => variance,
            Term::GaussMarkov { variance, tau_c } if GM_PEAK * tau_c <= 1.0 => {
                let phi = (-1.0 / (fs * tau_c)).exp();
                variance * (1.0 + phi) / ((1.0 - phi) * fs)
            }
            Term::Resonance {
                variance,
                freq,
                tau,
                skew,
            } if tau <= 1.0 => {
                // σ²·Re[(1 − iβ)(1 + z)/(1 − z)]/fs: its spectrum at zero frequency.
                let (u, theta) = basis::resonance_rates(freq, tau, fs);
                let z = rustfft::num_complex::Complex64::from_polar((-u).exp(), theta);
                let bound = basis::quadrature_bound(u, theta);
                let beta = if bound.is_finite() { skew * bound } else { 0.0 };
                let zero = rustfft::num_complex::Complex64::new(1.0, -beta) * (1.0 + z) / (1.0 - z);
                variance * zero.re / fs
            }
            _ => 0.0,
        }
    }

    /// What the term adds to the datasheet's K² over a record of `record`
    /// seconds: the random walk itself, and the short-τ walk rate
    /// 2σ²/τc of a Gauss–Markov term whose hump lies beyond the record (over the
    /// record it rises like a walk). A bump within the record is a bias state of
    /// its own and adds nothing: taken as K it would inflate an EKF's bias
    /// process noise by the bump's height over the walk's.
    pub fn walk_share(&self, record: f64) -> f64 {
        match *self {
            Term::RandomWalk { variance } => variance,
            Term::GaussMarkov { variance, tau_c } if tau_c > 1.0 && GM_PEAK * tau_c > record => {
                2.0 * variance / tau_c
            }
            _ => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_and_parameters_round_trip() {
        let terms = [
            Term::White { variance: 2.0 },
            Term::GaussMarkov {
                variance: 1.0,
                tau_c: 3.0,
            },
            Term::Resonance {
                variance: 1.0,
                freq: 5.0,
                tau: 0.1,
                skew: -0.5,
            },
        ];
        for t in terms {
            let kind = Kind::from_name(t.kind().name()).unwrap();
            assert_eq!(Term::new(kind, &t.parameters()).unwrap(), t);
            assert_eq!(t.parameters().len(), kind.parameter_names().len());
            assert_eq!(t.free(100.0).len(), kind.coordinate_names().len());
        }
        assert!(Kind::from_name("pink").is_err());
        assert!(Term::new(Kind::Tone, &[1.0]).is_err());
        assert!(Term::new(Kind::Tone, &[1.0, 0.0]).is_err());
        assert!(Term::new(Kind::Resonance, &[1.0, 1.0, 1.0, 1.5]).is_err());
        assert!(Term::new(Kind::White, &[-1.0]).is_err());
    }

    #[test]
    fn gradients_are_the_derivatives_of_the_curve() {
        let fs = 100.0;
        let tau = 0.37;
        let m = tau * fs;
        let t = Term::Resonance {
            variance: 2.0,
            freq: 7.0,
            tau: 0.05,
            skew: 0.3,
        };
        let g = t.gradient(tau, m, fs, 1.0);
        let skewed = |s: f64| {
            Term::Resonance {
                variance: 2.0,
                freq: 7.0,
                tau: 0.05,
                skew: s,
            }
            .allan_variance(tau, m, fs, 1.0)
        };
        let numeric = (skewed(0.31) - skewed(0.29)) / 0.02;
        assert!((g[3] / numeric - 1.0).abs() < 1e-6, "{g:?} {numeric}");
        assert_eq!(g[0], t.unit_variance(tau, m, fs, 1.0));
    }
}
