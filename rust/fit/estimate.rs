//! The weighted log-space fit of a noise model of fixed structure.
//!
//! Data: ln σ̂²ᵢ corrected for its bias, yᵢ = ln σ̂²ᵢ − [ψ(νᵢ/2) − ln(νᵢ/2)], with
//! sampling variance vᵢ = ψ′(νᵢ/2) (νᵢ the EDF; see `special`). Loss
//!
//! ```text
//! L(θ, δ²) = Σ ωᵢ [ ln(vᵢ + δ²) + (yᵢ − ln Mᵢ(θ))² / (vᵢ + δ²) ]
//! ```
//!
//! (−2 log-likelihood of independent normal log-estimates up to a constant), with
//! Mᵢ(θ) = Σⱼ θⱼ bⱼ(τᵢ) the model, θ ≥ 0 the terms' variance parameters and:
//! - ωᵢ ≤ 1 the share of an octave of log τ that tau i stands for (half the
//!   distance to its neighbours, in octaves). Overlapping Allan variances an
//!   octave apart are roughly independent, denser ones strongly correlated, so
//!   each octave of the curve carries the same evidence whatever the grid: the
//!   loss approximates one integral over log τ, and octave, 5, 10, 20 and 50 taus
//!   per decade give the same coefficients.
//! - δ² a model-discrepancy variance (relative, on the Allan variance), fitted by
//!   maximum likelihood. A real sensor follows no finite model to the 10⁻³ its
//!   short-tau estimates resolve (its filter, quantization); δ caps the weight of
//!   any tau at ω/δ², so a few-percent misfit there cannot outweigh the long taus.
//!   On data the model describes, δ → 0 and the fit is the plain EDF-weighted one.
//!
//! For fixed δ² the loss is minimised over θ ≥ 0 by Gauss–Newton steps, each an
//! NNLS problem (ln M linearised at the current model M⁰: rᵢ ≈ (zᵢ − Mᵢ)/M⁰ᵢ with
//! zᵢ = M⁰ᵢ(yᵢ − ln M⁰ᵢ + 1)), halving a step that does not lower the loss. δ² then
//! solves ∂L/∂δ² = 0 (bisection), and the two alternate to convergence.

use faer::Mat;

use super::basis::{self, IEEE_TERMS};
use super::filter::OutputFilter;
use super::nnls::nnls;
use super::special::{digamma_minus_log, trigamma};
use crate::error::{CoreError, CoreResult};

/// One channel's Allan variance in log form, with the weights of the loss.
#[derive(Debug, Clone)]
pub struct Data {
    pub taus: Vec<f64>,
    /// Cluster sizes τ·fs.
    pub m: Vec<f64>,
    pub y: Vec<f64>,
    pub v: Vec<f64>,
    pub omega: Vec<f64>,
    /// Per tau, the white term's factor through the sensor's output filter
    /// (`filter::OutputFilter::white_factors`; 1 without one).
    pub white: Vec<f64>,
    /// Per tau, ∂(that factor)/∂ln(white level the filter was measured against)
    /// (`filter::OutputFilter::level_factors`), and the level's relative variance:
    /// what the covariance adds for the level's uncertainty (0 without a filter).
    pub white_level: Vec<f64>,
    pub level_var: f64,
}

fn invalid(msg: String) -> CoreError {
    CoreError::InvalidArgument(msg)
}

impl Data {
    /// Check and transform `taus` (s, increasing), `var` (> 0), `edf` (> 0).
    pub fn new(taus: &[f64], var: &[f64], edf: &[f64], fs: f64) -> CoreResult<Data> {
        let n = taus.len();
        if n == 0 {
            return Err(invalid("taus must not be empty".into()));
        }
        if var.len() != n || edf.len() != n {
            return Err(invalid(format!(
                "taus, var and edf must have the same length; got {}, {} and {}",
                n,
                var.len(),
                edf.len()
            )));
        }
        if !(fs.is_finite() && fs > 0.0) {
            return Err(invalid(format!("fs must be finite and > 0; got {fs}")));
        }
        for (i, &t) in taus.iter().enumerate() {
            if !(t.is_finite() && t > 0.0) {
                return Err(invalid(format!(
                    "taus must be finite and > 0; taus[{i}] = {t}"
                )));
            }
            if i > 0 && t <= taus[i - 1] {
                return Err(invalid(format!(
                    "taus must be strictly increasing; taus[{}] = {} >= taus[{i}] = {t}",
                    i - 1,
                    taus[i - 1]
                )));
            }
        }
        for (name, values) in [("var", var), ("edf", edf)] {
            if let Some((i, v)) = values
                .iter()
                .enumerate()
                .find(|(_, v)| !(v.is_finite() && **v > 0.0))
            {
                return Err(invalid(format!(
                    "{name} must be finite and > 0; {name}[{i}] = {v}"
                )));
            }
        }
        let y = (0..n)
            .map(|i| var[i].ln() - digamma_minus_log(edf[i] / 2.0))
            .collect();
        let v = edf.iter().map(|e| trigamma(e / 2.0)).collect();
        Ok(Data {
            taus: taus.to_vec(),
            m: taus.iter().map(|t| t * fs).collect(),
            y,
            v,
            omega: octave_shares(taus),
            white: vec![1.0; n],
            white_level: vec![0.0; n],
            level_var: 0.0,
        })
    }

    /// The same data with the white term seen through `filter`.
    pub fn with_filter(mut self, filter: Option<&OutputFilter>) -> Data {
        if let Some(f) = filter {
            self.white = f.white_factors(&self.m);
            if f.level_std() > 0.0 {
                if let Ok(slope) = f.level_factors(&self.m) {
                    self.white_level = slope;
                    self.level_var = f.level_std().powi(2);
                }
            }
        }
        self
    }

    /// The same data without the white level's uncertainty: what a search judges
    /// terms by (the level, one number for every tau, enters the reported
    /// covariance only).
    pub fn judged(&self) -> Data {
        Data {
            level_var: 0.0,
            ..self.clone()
        }
    }

    /// Value of each IEEE basis function at tau `i`, the white one through the
    /// output filter.
    pub fn ieee(&self, i: usize) -> [f64; IEEE_TERMS] {
        let mut b = basis::ieee(self.taus[i]);
        b[1] *= self.white[i];
        b
    }

    pub fn len(&self) -> usize {
        self.taus.len()
    }

    pub fn is_empty(&self) -> bool {
        self.taus.is_empty()
    }

    /// Σω: the number of octaves' worth of independent evidence.
    pub fn n_eff(&self) -> f64 {
        self.omega.iter().sum()
    }
}

/// ωᵢ: half the log-distance to each neighbour, in octaves, at most 1 (the end
/// points take the full distance to their one neighbour).
pub fn octave_shares(taus: &[f64]) -> Vec<f64> {
    let n = taus.len();
    let l: Vec<f64> = taus.iter().map(|t| t.log2()).collect();
    (0..n)
        .map(|i| {
            let w = match (i, n) {
                (_, 1) => 1.0,
                (0, _) => l[1] - l[0],
                (i, n) if i == n - 1 => l[i] - l[i - 1],
                (i, _) => 0.5 * (l[i + 1] - l[i - 1]),
            };
            w.min(1.0)
        })
        .collect()
}

/// Model values Σⱼ θⱼ bᵢⱼ for a basis given as an n × k matrix.
pub fn evaluate(basis: &Mat<f64>, theta: &[f64]) -> Vec<f64> {
    (0..basis.nrows())
        .map(|i| (0..basis.ncols()).map(|j| basis[(i, j)] * theta[j]).sum())
        .collect()
}

/// The loss L(θ, δ²) for model values `model` (∞ where the model is not > 0).
pub fn loss(data: &Data, model: &[f64], d2: f64) -> f64 {
    let mut s = 0.0;
    for (i, &m) in model.iter().enumerate().take(data.len()) {
        if m.is_nan() || m <= 0.0 {
            return f64::INFINITY;
        }
        let r = data.y[i] - m.ln();
        let w = data.v[i] + d2;
        s += data.omega[i] * (w.ln() + r * r / w);
    }
    s
}

/// The δ² ≥ 0 that minimises the loss for fixed model values.
pub fn ml_discrepancy(data: &Data, model: &[f64]) -> f64 {
    let r2: Vec<f64> = (0..data.len())
        .map(|i| (data.y[i] - model[i].ln()).powi(2))
        .collect();
    // dL/dδ² = Σ ω [1/(v+δ²) − r²/(v+δ²)²]; increasing in δ² past its root.
    let slope = |d2: f64| -> f64 {
        (0..data.len())
            .map(|i| {
                let w = data.v[i] + d2;
                data.omega[i] * (1.0 / w - r2[i] / (w * w))
            })
            .sum()
    };
    if slope(0.0) >= 0.0 {
        return 0.0;
    }
    let (mut lo, mut hi) = (1e-16f64, 1.0f64);
    while slope(hi) < 0.0 && hi < 1e6 {
        hi *= 10.0;
    }
    for _ in 0..100 {
        let mid = (lo * hi).sqrt();
        if slope(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi / lo < 1.0 + 1e-9 {
            break;
        }
    }
    (lo * hi).sqrt()
}

/// One least-squares problem: the data, the design (one column per term) and
/// which columns may be non-zero.
#[derive(Clone, Copy)]
pub struct Problem<'a> {
    pub data: &'a Data,
    pub basis: &'a Mat<f64>,
    pub allowed: &'a [bool],
}

/// Minimise the loss over θ ≥ 0 (θⱼ = 0 where `!allowed[j]`) for fixed δ².
/// Returns θ and the model values.
pub fn solve_theta(
    problem: Problem<'_>,
    d2: f64,
    start: Option<&[f64]>,
    max_steps: usize,
) -> CoreResult<(Vec<f64>, Vec<f64>)> {
    let Problem {
        data,
        basis,
        allowed,
    } = problem;
    let (n, k) = (basis.nrows(), basis.ncols());
    let mut theta = vec![0.0; k];
    let mut model: Vec<f64> = data.y.iter().map(|y| y.exp()).collect();
    let mut current = f64::INFINITY;
    if let Some(s) = start {
        let m = evaluate(basis, s);
        let l = loss(data, &m, d2);
        if l.is_finite() {
            theta = s.to_vec();
            model = m;
            current = l;
        }
    }
    for _ in 0..max_steps {
        let sw: Vec<f64> = (0..n)
            .map(|i| (data.omega[i] / (data.v[i] + d2)).sqrt() / model[i])
            .collect();
        let z: Vec<f64> = (0..n)
            .map(|i| model[i] * (data.y[i] - model[i].ln() + 1.0) * sw[i])
            .collect();
        let mut scale = vec![0.0; k];
        for i in 0..n {
            for (j, s) in scale.iter_mut().enumerate() {
                *s += (basis[(i, j)] * sw[i]).powi(2);
            }
        }
        for s in scale.iter_mut() {
            *s = if *s > 0.0 && s.is_finite() {
                1.0 / s.sqrt()
            } else {
                1.0
            };
        }
        let a = Mat::from_fn(n, k, |i, j| basis[(i, j)] * sw[i] * scale[j]);
        let x = nnls(&a, &z, allowed)?;
        let proposal: Vec<f64> = (0..k).map(|j| x[j] * scale[j]).collect();
        // Accept the step, or halve it until the loss goes down.
        let mut step = proposal;
        let mut accepted = None;
        for _ in 0..20 {
            let m = evaluate(basis, &step);
            let l = loss(data, &m, d2);
            if l.is_finite() && (l <= current || !current.is_finite()) {
                accepted = Some((step.clone(), m, l));
                break;
            }
            if !current.is_finite() {
                break;
            }
            for j in 0..k {
                step[j] = 0.5 * (step[j] + theta[j]);
            }
        }
        let Some((t, m, l)) = accepted else {
            break;
        };
        let done = current.is_finite() && current - l <= 1e-10 * (1.0 + l.abs());
        theta = t;
        model = m;
        current = l;
        if done {
            break;
        }
    }
    if !current.is_finite() {
        return Err(CoreError::Numerical(
            "noise-model fit found no model with a positive Allan variance at every tau".into(),
        ));
    }
    Ok((theta, model))
}

/// A fit of fixed structure with δ² estimated.
#[derive(Debug, Clone)]
pub struct Solution {
    pub theta: Vec<f64>,
    pub model: Vec<f64>,
    pub d2: f64,
    pub loss: f64,
}

/// Alternate θ and δ² to the joint minimum of the loss.
pub fn solve_joint(
    problem: Problem<'_>,
    d2_start: f64,
    start: Option<&[f64]>,
) -> CoreResult<Solution> {
    let data = problem.data;
    let mut d2 = d2_start;
    let (mut theta, mut model) = solve_theta(problem, d2, start, 50)?;
    for _ in 0..30 {
        let next = ml_discrepancy(data, &model);
        let settled = (next - d2).abs() <= 1e-6 * next.max(1e-12);
        d2 = next;
        if settled {
            break;
        }
        (theta, model) = solve_theta(problem, d2, Some(&theta), 50)?;
    }
    let loss = loss(data, &model, d2);
    Ok(Solution {
        theta,
        model,
        d2,
        loss,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octave_shares_follow_the_grid() {
        let octave: Vec<f64> = (0..10).map(|k| 2f64.powi(k)).collect();
        assert!(octave_shares(&octave)
            .iter()
            .all(|w| (w - 1.0).abs() < 1e-12));
        let dense: Vec<f64> = (0..100).map(|k| 10f64.powf(k as f64 / 50.0)).collect();
        let w = octave_shares(&dense);
        let per = (10f64.powf(0.02)).log2();
        assert!(w.iter().all(|x| (x - per).abs() < 1e-12));
        // Two decades of 50-per-decade taus weigh like two decades of octaves.
        assert!((w.iter().sum::<f64>() - 100.0 * per).abs() < 1e-9);
    }

    #[test]
    fn discrepancy_is_zero_when_residuals_are_within_noise() {
        let taus: Vec<f64> = (0..12).map(|k| 2f64.powi(k)).collect();
        let var = vec![1.0; 12];
        let data = Data::new(&taus, &var, &[1e4; 12], 100.0).unwrap();
        let model: Vec<f64> = data.y.iter().map(|y| y.exp()).collect();
        assert_eq!(ml_discrepancy(&data, &model), 0.0);
        // A uniform 10 % misfit (0.0953 in ln) is recovered as δ² ≈ r² − v.
        let off: Vec<f64> = model.iter().map(|m| m * 1.1).collect();
        let d2 = ml_discrepancy(&data, &off);
        let r2 = 1.1f64.ln().powi(2);
        assert!((d2 - (r2 - data.v[0])).abs() < 1e-6 * r2, "{d2}");
    }
}
