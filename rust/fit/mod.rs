//! The noise model of an inertial sensor, fitted to its Allan variance.
//!
//! ```text
//! σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)·B² + K²τ/3 + R²τ²/2 + Σₖ qₖ²·g(τ; τcₖ)
//!         + s²·h(τ; f₀) + r²·o(τ; f_r, τr, s)
//! ```
//!
//! the IEEE Std 952 / 1293 terms plus up to [`MAX_GM`] = 3 first-order
//! Gauss–Markov bias terms of variance qₖ² and correlation time τcₖ (three: a
//! MEMS sensor's own filter, a bump of correlated bias, and slow wander), and
//! up to [`search::MAX_TONES`] sinusoids (tones) of variance s² (amplitude √2·s)
//! and frequency f₀ and at most one resonance (damped oscillator, second-order
//! Gauss–Markov) of variance r², frequency f_r, damping time τr and skew s in
//! [−1, 1], its quadrature part (0 for a plain resonance; a sensor's
//! second-order filter has one) (`basis`). The estimator
//! (`estimate`) is a weighted least-squares fit of ln σ̂² with weights from the
//! EDF, the share of an octave each tau stands for, and a model-discrepancy
//! variance fitted by maximum likelihood; the structure (`search`) is chosen by
//! BIC, the correlation times by grid and golden-section search (variable
//! projection). The covariance of the parameters is the inverse Fisher
//! information of that loss, (JᵀWJ)⁻¹, in the variances and ln τc.
//!
//! References: IEEE Std 952-1997, Annex C; Guerrier, Skaloud, Stebler,
//! Victoria-Feser, "Wavelet-variance-based estimation for composite stochastic
//! processes", JASA 108 (2013) (the AR1 moments and why taus are not
//! independent); Paule & Mandel (1982) for a fitted between-"study" variance;
//! Lawson & Hanson (1974) for NNLS.

pub mod basis;
pub mod estimate;
pub mod filter;
pub mod nnls;
pub mod oscillators;
pub mod search;
pub mod special;

pub use basis::{FLICKER_FACTOR, IEEE_TERMS, IEEE_TERM_NAMES};

use crate::error::{CoreError, CoreResult};
use estimate::Data;
use filter::OutputFilter;
use search::Candidate;

/// Most Gauss–Markov terms a model may have.
pub const MAX_GM: usize = 3;

pub use search::MAX_TONES;

/// First slot of the tones in the parameter covariance: s², then ln f₀, per tone.
pub const SINE_SLOT: usize = IEEE_TERMS + 2 * MAX_GM;

/// First slot of the resonance in the parameter covariance: r², ln f_r, ln τr, s.
pub const RESONANCE_SLOT: usize = SINE_SLOT + 2 * MAX_TONES;

/// Slot of the resonance's skew s in the parameter covariance.
pub const SKEW_SLOT: usize = RESONANCE_SLOT + 3;

/// First slot of the bounded motion in the parameter covariance: σθ², ln τc.
pub const MOTION_SLOT: usize = RESONANCE_SLOT + 4;

/// Slots of the parameter covariance: Q², N², B², K², R², then (q², ln τc) per
/// Gauss–Markov term, then (s², ln f₀) per tone, then (r², ln f_r, ln τr, s) of
/// the resonance, then (σθ², ln τc) of the bounded motion.
pub const PARAMETERS: usize = MOTION_SLOT + 2;

/// A fitted resonance: variance r², frequency f_r (Hz), damping time τr (s) and
/// skew in [−1, 1] (`basis::skewed_resonance`; 0 for a plain one).
pub type ResonanceFit = (f64, f64, f64, f64);

/// The tone (s², f₀), resonance and bounded motion (σθ², τc) terms of a model:
/// up to [`MAX_TONES`] tones, at most one of the others.
pub type Oscillators<'a> = (&'a [(f64, f64)], &'a [ResonanceFit], &'a [(f64, f64)]);

/// What [`fit_noise`] may use.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    /// Which of Q, N, B, K, R may enter the model.
    pub ieee: [bool; IEEE_TERMS],
    /// Gauss–Markov terms: the most allowed (`select`) or the exact number.
    pub gm: usize,
    /// Tones: the most allowed (`select`, at most [`MAX_TONES`]) or the exact
    /// number fitted.
    pub tones: usize,
    /// A resonance: may enter (`select`) or is fitted (not `select`).
    pub resonance: bool,
    /// A bounded motion: may enter (`select`) or is fitted (not `select`).
    pub motion: bool,
    /// Choose the structure by BIC (`true`), or fit exactly the terms given.
    pub select: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            ieee: [true; IEEE_TERMS],
            gm: MAX_GM,
            tones: MAX_TONES,
            resonance: true,
            motion: true,
            select: true,
        }
    }
}

/// One channel's fitted model.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseFit {
    /// (Q², N², B², K², R²), each ≥ 0 (0: not in the model).
    pub ieee: [f64; IEEE_TERMS],
    /// Variance q² and correlation time τc (s) of each Gauss–Markov term in the
    /// model, by increasing τc.
    pub gm: Vec<(f64, f64)>,
    /// Variance s² and frequency f₀ (Hz) of each tone, by increasing frequency.
    pub sine: Vec<(f64, f64)>,
    /// Variance r², frequency f_r (Hz), damping time τr (s) and skew of the
    /// resonance, if the model has one.
    pub resonance: Vec<ResonanceFit>,
    /// Variance σθ² of the bounded angle (or velocity) and its correlation time
    /// τc (s), if the model has a bounded motion.
    pub motion: Vec<(f64, f64)>,
    /// Covariance over [`PARAMETERS`] slots (0 for parameters not in the model).
    pub cov: Vec<Vec<f64>>,
    /// Model discrepancy δ: relative standard deviation of the Allan variance
    /// that the model does not explain beyond the estimates' own scatter.
    pub discrepancy: f64,
    /// Σ ωᵢ rᵢ²/vᵢ: the weighted residual sum with the sampling variance alone.
    pub chi2: f64,
    /// Σ ωᵢ: octaves of independent evidence.
    pub n_eff: f64,
    /// Free parameters of the model.
    pub parameters: usize,
    /// Bayesian information criterion of the chosen structure.
    pub bic: f64,
}

/// Fit one channel: `taus` (s, increasing), `var` (σ̂² > 0) and `edf` (> 0) per
/// tau, `fs` the sample rate of the data behind them, `filter` the sensor's
/// output filter if the spectrum showed one (the white term is seen through it).
pub fn fit_noise(
    taus: &[f64],
    var: &[f64],
    edf: &[f64],
    fs: f64,
    opts: &Options,
    filter: Option<&OutputFilter>,
) -> CoreResult<NoiseFit> {
    if opts.tones > MAX_TONES {
        return Err(CoreError::InvalidArgument(format!(
            "at most {MAX_TONES} tones; got {}",
            opts.tones
        )));
    }
    if opts.gm > MAX_GM {
        return Err(CoreError::InvalidArgument(format!(
            "at most {MAX_GM} Gauss-Markov terms; got {}",
            opts.gm
        )));
    }
    let data = Data::new(taus, var, edf, fs)?.with_filter(filter);
    let chosen = if opts.select {
        let selected = |motion: bool| -> CoreResult<Candidate> {
            let kinds = (opts.tones, opts.resonance, motion);
            let best = search::select(&data, fs, opts.ieee, opts.gm, kinds)?;
            let best = search::prefer_random_walk(&data, fs, opts.ieee, opts.gm, kinds, best)?;
            prune_insignificant(&data, fs, best)
        };
        let best = selected(opts.motion)?;
        // A motion is searched last, on what the search had then; pruning and the
        // walk's check after it can leave a structure the search without it beats
        // (on the first half of the VN-100 accelerometer X, by 1.9, and it predicted
        // the second half at 57 % of taus against 87 %). It stays only if it wins.
        if best.motion.is_some() {
            let without = selected(false)?;
            if without.score() <= best.score() {
                without
            } else {
                best
            }
        } else {
            best
        }
    } else {
        fixed_structure(&data, fs, opts)?
    };
    Ok(summarise(&data, fs, &chosen))
}

/// The structure `opts` names, fitted as it is (no selection): the IEEE terms and
/// Gauss–Markov terms, then the tone, the resonance and the bounded motion each
/// searched on top of what came before. Any of them may be the only term.
fn fixed_structure(data: &Data, fs: f64, opts: &Options) -> CoreResult<Candidate> {
    let base = search::fit_structure(data, fs, opts.ieee, 0, 0.0, &[]);
    let d2 = base.as_ref().map_or(0.0, |b| b.solution.d2);
    let mut current = if opts.gm == 0 {
        base.ok()
    } else {
        Some(search::fit_structure(
            data,
            fs,
            opts.ieee,
            opts.gm,
            d2,
            &[],
        )?)
    };
    let shape = |c: &Option<Candidate>| match c {
        Some(c) => (c.gm_tau.clone(), c.sine, c.resonance, c.solution.d2),
        None => (Vec::new(), search::Tones::NONE, None, d2),
    };
    for _ in 0..opts.tones {
        let (times, tones, _, d2) = shape(&current);
        let toned = search::with_sine(data, fs, opts.ieee, (&times, tones, None), d2, false)?;
        current = toned.or(current);
    }
    if opts.resonance {
        // The resonance with and without a quadrature part; the lower BIC is its fit.
        let (times, sine, _, d2) = shape(&current);
        let mut fitted: Option<Candidate> = None;
        for skewed in [false, true] {
            let shape = (times.as_slice(), sine, skewed);
            if let Some(c) = search::with_resonance(data, fs, opts.ieee, shape, d2, false)? {
                if fitted.as_ref().is_none_or(|f| c.bic < f.bic) {
                    fitted = Some(c);
                }
            }
        }
        current = fitted.or(current);
    }
    if opts.motion {
        let (times, sine, res, d2) = shape(&current);
        let moved = search::with_motion(data, fs, opts.ieee, (&times, sine, res), d2, false)?;
        current = moved.or(current);
    }
    current.ok_or_else(|| {
        CoreError::Numerical(
            "noise-model fit found no model with a positive Allan variance at every tau".into(),
        )
    })
}

/// Smallest z = variance / standard uncertainty a selected term may have.
const MIN_Z: f64 = 2.0;

/// A term below [`MIN_Z`] goes only if its removal raises the loss by less than
/// this many BIC penalties: on a real sensor the fitted discrepancy inflates
/// every uncertainty, and a term can be needed (removing it raises the loss by
/// tens) while its z is small.
const PRUNE_PENALTIES: f64 = 2.0;

/// Remove, one at a time, a selected term whose variance is less than
/// [`MIN_Z`] standard uncertainties above 0 and whose removal the fit barely
/// notices: BIC admits a term that explains a correlated wiggle of a few
/// long-tau estimates (they are less independent than an octave each), this
/// keeps only terms the data constrain. Gauss–Markov terms are tried before
/// IEEE terms (where a fast one looks white or a slow one like a walk, the
/// datasheet term is kept), each group by increasing z; a tone or a resonance
/// before either.
/// The last term stays.
fn prune_insignificant(data: &Data, fs: f64, mut best: Candidate) -> CoreResult<Candidate> {
    // The allowance holds for each removal and, cumulatively, against the
    // selected fit: each removal raises δ and so makes the next one look cheaper
    // (without the total, terms fall in a cascade); without the per-step bound,
    // two free removals paid for a costly third (K and R, nearly collinear with B
    // at the longest taus, went at a cost of 0.9 and 1.5, then B at 7.6: a
    // VN-100 gyro's flat part at 30–130 s was left undescribed).
    let allowance = PRUNE_PENALTIES * data.n_eff().max(2.0).ln();
    let selected = best.solution.loss;
    let mut removed = 0.0;
    'outer: loop {
        let fit = summarise(data, fs, &best);
        let active = fit.ieee.iter().filter(|v| **v > 0.0).count()
            + fit.gm.len()
            + fit.sine.len()
            + fit.resonance.len()
            + fit.motion.len();
        if active <= 1 {
            return Ok(best);
        }
        let weak = |slots: Vec<(usize, f64)>| {
            let mut out: Vec<(usize, f64)> = slots
                .into_iter()
                .map(|(slot, v)| (slot, v / fit.cov[slot][slot].sqrt()))
                .filter(|(_, z)| z.is_finite() && *z < MIN_Z)
                .collect();
            out.sort_by(|a, b| a.1.total_cmp(&b.1));
            out
        };
        let gm_slots = (0..fit.gm.len())
            .map(|k| (IEEE_TERMS + 2 * k, fit.gm[k].0))
            .collect();
        let ieee_slots = (0..IEEE_TERMS)
            .filter(|&j| fit.ieee[j] > 0.0)
            .map(|j| (j, fit.ieee[j]))
            .collect();
        let sine_slots = (fit.sine.iter().enumerate()).map(|(k, s)| (SINE_SLOT + 2 * k, s.0));
        let res_slots = fit.resonance.iter().map(|r| (RESONANCE_SLOT, r.0));
        // A quadrature part the data do not constrain: the plain resonance.
        let quadrature = (fit.resonance.iter())
            .filter(|r| r.3 != 0.0)
            .map(|r| (SKEW_SLOT, r.3.abs()));
        let motion_slots = fit.motion.iter().map(|r| (MOTION_SLOT, r.0));
        let mut order = weak(
            quadrature
                .chain(sine_slots)
                .chain(res_slots)
                .chain(motion_slots)
                .collect(),
        );
        order.extend(weak(gm_slots));
        order.extend(weak(ieee_slots));
        for (slot, _) in order {
            let mut ieee = best.ieee;
            let mut times: Vec<f64> = fit.gm.iter().map(|g| g.1).collect();
            let tones: Vec<f64> = fit.sine.iter().map(|s| s.1).collect();
            let mut sine = search::Tones::from_slice(&tones);
            let mut resonance = (best.resonance).filter(|_| !fit.resonance.is_empty());
            let mut motion = fit.motion.first().map(|r| r.1);
            if slot < IEEE_TERMS {
                ieee[slot] = false;
            } else if (SINE_SLOT..RESONANCE_SLOT).contains(&slot) {
                sine = sine.without((slot - SINE_SLOT) / 2);
            } else if slot == RESONANCE_SLOT {
                resonance = None;
            } else if slot == SKEW_SLOT {
                resonance = resonance.map(|r| search::Resonance { skewed: false, ..r });
            } else if slot == MOTION_SLOT {
                motion = None;
            } else {
                times.remove((slot - IEEE_TERMS) / 2);
            }
            let extras = (sine, resonance, motion);
            if let Ok(next) = search::candidate(data, fs, ieee, times, extras, best.solution.d2) {
                let step = next.solution.loss - best.solution.loss;
                let total = next.solution.loss - selected;
                if step < allowance && total < allowance * (removed + 1.0) {
                    best = next;
                    removed += 1.0;
                    continue 'outer;
                }
            }
        }
        return Ok(best);
    }
}

fn summarise(data: &Data, fs: f64, c: &Candidate) -> NoiseFit {
    let theta = &c.solution.theta;
    let mut ieee = [0.0; IEEE_TERMS];
    ieee.copy_from_slice(&theta[..IEEE_TERMS]);
    let gm: Vec<(f64, f64)> = c
        .gm_tau
        .iter()
        .enumerate()
        .filter(|(k, _)| theta[IEEE_TERMS + k] > 0.0)
        .map(|(k, &t)| (theta[IEEE_TERMS + k], t))
        .collect();
    let tone_column = IEEE_TERMS + c.gm_tau.len();
    let mut sine: Vec<(f64, f64)> = (c.sine.as_slice().iter().enumerate())
        .map(|(k, &f)| (theta[tone_column + k], f))
        .filter(|s| s.0 > 0.0)
        .collect();
    sine.sort_by(|a, b| a.1.total_cmp(&b.1));
    let res_column = tone_column + c.sine.len();
    let res_columns = c.resonance.map_or(0, search::Resonance::columns);
    let resonance: Vec<ResonanceFit> = c
        .resonance
        .map(|r| {
            let (r2, skew) = r.variance_and_skew(&theta[res_column..], fs);
            (r2, r.freq, r.tau, skew)
        })
        .filter(|r| r.0 > 0.0)
        .into_iter()
        .collect();
    let motion_column = res_column + res_columns;
    let motion: Vec<(f64, f64)> = c
        .motion
        .map(|t| (theta[motion_column], t))
        .filter(|r| r.0 > 0.0)
        .into_iter()
        .collect();
    let chi2 = (0..data.len())
        .map(|i| data.omega[i] * (data.y[i] - c.solution.model[i].ln()).powi(2) / data.v[i])
        .sum();
    NoiseFit {
        cov: covariance(
            data,
            fs,
            &ieee,
            &gm,
            (&sine, &resonance, &motion),
            c.solution.d2,
        ),
        ieee,
        gm,
        sine,
        resonance,
        motion,
        discrepancy: c.solution.d2.sqrt(),
        chi2,
        n_eff: data.n_eff(),
        parameters: search::parameters(theta, c.resonance, c.motion.is_some()),
        bic: c.bic,
    }
}

/// Model Allan variance of every term at `taus`: row i holds the five IEEE
/// terms, then one value per Gauss–Markov term (q², τc), then one per tone
/// (s², f₀), then one per resonance (r², f_r, τr, skew), then one per bounded motion
/// (σθ², τc). The white term is seen through `filter`, if given.
pub fn terms(
    taus: &[f64],
    fs: f64,
    ieee: &[f64; IEEE_TERMS],
    gm: &[(f64, f64)],
    (sine, resonance, motion): Oscillators,
    filter: Option<&OutputFilter>,
) -> Vec<Vec<f64>> {
    taus.iter()
        .map(|&t| {
            let mut b = basis::ieee(t);
            if let Some(f) = filter {
                b[1] *= f.white_factor(t * fs);
            }
            let mut row: Vec<f64> = (0..IEEE_TERMS).map(|j| b[j] * ieee[j]).collect();
            row.extend(
                gm.iter()
                    .map(|&(q2, tc)| q2 * basis::gauss_markov(t * fs, basis::gm_rate(tc, fs))),
            );
            row.extend(
                sine.iter()
                    .map(|&(s2, f0)| s2 * basis::sinusoid(t * fs, f0 / fs)),
            );
            row.extend(resonance.iter().map(|&(r2, f, tr, skew)| {
                let (u, theta) = basis::resonance_rates(f, tr, fs);
                r2 * basis::skewed_resonance(t * fs, u, theta, skew)
            }));
            row.extend(
                motion
                    .iter()
                    .map(|&(v, tc)| v * basis::motion(t, t * fs, basis::gm_rate(tc, fs))),
            );
            row
        })
        .collect()
}

/// Inverse Fisher information of the loss at the solution.
fn covariance(
    data: &Data,
    fs: f64,
    ieee: &[f64; IEEE_TERMS],
    gm: &[(f64, f64)],
    (sine, resonance, motion): Oscillators,
    d2: f64,
) -> Vec<Vec<f64>> {
    // Parameter slots in use and, per tau, ∂M/∂p.
    let mut slots: Vec<usize> = (0..IEEE_TERMS).filter(|&j| ieee[j] > 0.0).collect();
    for k in 0..gm.len() {
        slots.push(IEEE_TERMS + 2 * k);
        slots.push(IEEE_TERMS + 2 * k + 1);
    }
    for k in 0..sine.len() {
        slots.push(SINE_SLOT + 2 * k);
        slots.push(SINE_SLOT + 2 * k + 1);
    }
    // A resonance at fs/2 sits on the bound of its frequency, where the sampled
    // curve is even in f_r − fs/2 (∂/∂f_r = 0): the frequency is then not a
    // free parameter and its variance is NaN (set below).
    let at_nyquist = resonance
        .first()
        .is_some_and(|r| r.1 >= 0.5 * fs * (1.0 - 1e-9));
    // A skew on its bound ±1 (the spectrum touches zero) is not free either:
    // its variance is NaN too.
    let skewed = resonance.first().is_some_and(|r| r.3 != 0.0);
    let on_skew_bound = resonance.first().is_some_and(|r| r.3.abs() >= 1.0 - 1e-9);
    if !resonance.is_empty() {
        slots.push(RESONANCE_SLOT);
        if !at_nyquist {
            slots.push(RESONANCE_SLOT + 1);
        }
        slots.push(RESONANCE_SLOT + 2);
        if skewed && !on_skew_bound {
            slots.push(SKEW_SLOT);
        }
    }
    if !motion.is_empty() {
        slots.push(MOTION_SLOT);
        slots.push(MOTION_SLOT + 1);
    }
    let h: f64 = 1e-4;
    let rows: Vec<(f64, Vec<f64>)> = (0..data.len())
        .map(|i| {
            let t = data.taus[i];
            let b = data.ieee(i);
            let gmv =
                |q2: f64, tc: f64| q2 * basis::gauss_markov(data.m[i], basis::gm_rate(tc, fs));
            let tone = |s2: f64, f0: f64| s2 * basis::sinusoid(data.m[i], f0 / fs);
            let osc = |r2: f64, f: f64, tr: f64, skew: f64| {
                let (u, theta) = basis::resonance_rates(f, tr, fs);
                r2 * basis::skewed_resonance(data.m[i], u, theta, skew)
            };
            let moving = |v: f64, tc: f64| v * basis::motion(t, data.m[i], basis::gm_rate(tc, fs));
            let model: f64 = (0..IEEE_TERMS).map(|j| b[j] * ieee[j]).sum::<f64>()
                + gm.iter().map(|&(q2, tc)| gmv(q2, tc)).sum::<f64>()
                + sine.iter().map(|&(s2, f0)| tone(s2, f0)).sum::<f64>()
                + resonance
                    .iter()
                    .map(|&(r2, f, tr, skew)| osc(r2, f, tr, skew))
                    .sum::<f64>()
                + motion.iter().map(|&(v, tc)| moving(v, tc)).sum::<f64>();
            let grad = slots
                .iter()
                .map(|&s| {
                    if s < IEEE_TERMS {
                        b[s]
                    } else if s >= MOTION_SLOT {
                        let (v, tc) = motion[0];
                        if s == MOTION_SLOT {
                            moving(1.0, tc)
                        } else {
                            (moving(v, tc * h.exp()) - moving(v, tc * (-h).exp())) / (2.0 * h)
                        }
                    } else if s >= RESONANCE_SLOT {
                        let (r2, f, tr, skew) = resonance[0];
                        let (e, ie) = (h.exp(), (-h).exp());
                        match s - RESONANCE_SLOT {
                            0 => osc(1.0, f, tr, skew),
                            1 => (osc(r2, f * e, tr, skew) - osc(r2, f * ie, tr, skew)) / (2.0 * h),
                            2 => (osc(r2, f, tr * e, skew) - osc(r2, f, tr * ie, skew)) / (2.0 * h),
                            // Linear in the skew: r²·κ times the quadrature form.
                            _ => {
                                let (u, theta) = basis::resonance_rates(f, tr, fs);
                                let bound = basis::quadrature_bound(u, theta);
                                r2 * bound * basis::resonance_parts(data.m[i], u, theta).1
                            }
                        }
                    } else if s >= SINE_SLOT {
                        let (s2, f0) = sine[(s - SINE_SLOT) / 2];
                        if (s - SINE_SLOT).is_multiple_of(2) {
                            tone(1.0, f0)
                        } else {
                            (tone(s2, f0 * h.exp()) - tone(s2, f0 * (-h).exp())) / (2.0 * h)
                        }
                    } else {
                        let (q2, tc) = gm[(s - IEEE_TERMS) / 2];
                        if (s - IEEE_TERMS).is_multiple_of(2) {
                            gmv(1.0, tc)
                        } else {
                            (gmv(q2, tc * h.exp()) - gmv(q2, tc * (-h).exp())) / (2.0 * h)
                        }
                    }
                })
                .map(|d| d / model)
                .collect();
            (data.omega[i] / (data.v[i] + d2), grad)
        })
        .collect();
    let fisher = |keep: &[usize]| -> Vec<Vec<f64>> {
        keep.iter()
            .map(|&a| {
                keep.iter()
                    .map(|&b| rows.iter().map(|(w, g)| w * g[a] * g[b]).sum())
                    .collect()
            })
            .collect()
    };
    // Near fs/2 a resonance's frequency and skew are nearly unidentified (its
    // curve is even in f_r − fs/2, and the quadrature part vanishes there), and
    // the information can be singular in them: they are then left out (NaN).
    let all: Vec<usize> = (0..slots.len()).collect();
    let without_oscillator: Vec<usize> = (0..slots.len())
        .filter(|&a| slots[a] != SKEW_SLOT && slots[a] != RESONANCE_SLOT + 1)
        .collect();
    let mut cov = vec![vec![0.0; PARAMETERS]; PARAMETERS];
    for &s in &slots {
        cov[s][s] = f64::NAN;
    }
    for keep in [all, without_oscillator] {
        if let Some(inv) = nnls::invert_spd(&fisher(&keep)) {
            for (a, &ka) in keep.iter().enumerate() {
                for (b, &kb) in keep.iter().enumerate() {
                    cov[slots[ka]][slots[kb]] = inv[a][b];
                }
            }
            break;
        }
    }
    if at_nyquist {
        cov[RESONANCE_SLOT + 1][RESONANCE_SLOT + 1] = f64::NAN;
    }
    if on_skew_bound {
        cov[SKEW_SLOT][SKEW_SLOT] = f64::NAN;
    }
    cov
}

#[cfg(test)]
mod tests {
    use super::*;

    const FS: f64 = 100.0;

    fn grid(per_decade: f64, lo: f64, hi: f64) -> Vec<f64> {
        let (a, b) = (
            (lo.log10() * per_decade).ceil() as i64,
            (hi.log10() * per_decade).floor() as i64,
        );
        let mut t: Vec<f64> = (a..=b)
            .map(|j| (10f64.powf(j as f64 / per_decade) * FS).round() / FS)
            .collect();
        t.dedup();
        t
    }

    fn curve(taus: &[f64], ieee: &[f64; 5], gm: &[(f64, f64)]) -> Vec<f64> {
        curve_with(taus, ieee, gm, (&[], &[], &[]))
    }

    /// The model's Allan variance at `taus`, every term summed.
    fn curve_with(
        taus: &[f64],
        ieee: &[f64; 5],
        gm: &[(f64, f64)],
        oscillators: Oscillators,
    ) -> Vec<f64> {
        terms(taus, FS, ieee, gm, oscillators, None)
            .iter()
            .map(|r| r.iter().sum())
            .collect()
    }

    fn edf_white(taus: &[f64], n: f64) -> Vec<f64> {
        taus.iter().map(|t| (n / (t * FS)).max(2.0)).collect()
    }

    /// Default fit of a noise-free curve: EDF 10⁶ at every tau (the log bias
    /// 1e-6 is negligible, and BIC does not chase rounding-level differences).
    fn fit_exact(taus: &[f64], var: &[f64]) -> NoiseFit {
        let edf = vec![1e6; taus.len()];
        fit_noise(taus, var, &edf, FS, &Options::default(), None).unwrap()
    }

    #[test]
    fn exact_five_term_curve_is_recovered_without_gm() {
        let truth = [0.0, 4e-6, 1e-6, 1e-10, 0.0];
        let taus = grid(10.0, 0.01, 2000.0);
        let var = curve(&taus, &truth, &[]);
        let fit = fit_exact(&taus, &var);
        assert!(fit.gm.is_empty(), "{:?}", fit.gm);
        assert!(fit.sine.is_empty(), "{:?}", fit.sine);
        assert!(fit.resonance.is_empty(), "{:?}", fit.resonance);
        for j in [1, 2, 3] {
            assert!(
                (fit.ieee[j] / truth[j] - 1.0).abs() < 1e-3,
                "{j}: {:?}",
                fit.ieee
            );
        }
        assert_eq!(fit.ieee[0], 0.0);
        assert_eq!(fit.ieee[4], 0.0);
        assert!(fit.discrepancy < 1e-3);
    }

    #[test]
    fn gauss_markov_terms_are_recovered() {
        let truth_gm = [(1e-6, 0.3), (4e-8, 200.0)];
        let ieee = [0.0, 1e-6, 0.0, 0.0, 0.0];
        for per_decade in [3.0103, 5.0, 20.0, 50.0] {
            let taus = grid(per_decade, 0.01, 1000.0);
            let var = curve(&taus, &ieee, &truth_gm);
            let fit = fit_exact(&taus, &var);
            assert_eq!(fit.gm.len(), 2, "{per_decade}: {fit:?}");
            assert!(fit.sine.is_empty(), "{per_decade}: {fit:?}");
            assert!(fit.resonance.is_empty(), "{per_decade}: {fit:?}");
            for (got, want) in fit.gm.iter().zip(truth_gm) {
                assert!(
                    (got.0 / want.0 - 1.0).abs() < 0.01,
                    "{per_decade}: {got:?} vs {want:?}"
                );
                assert!(
                    (got.1 / want.1 - 1.0).abs() < 0.01,
                    "{per_decade}: {got:?} vs {want:?}"
                );
            }
            assert!((fit.ieee[1] / ieee[1] - 1.0).abs() < 0.01);
        }
    }

    #[test]
    fn a_tone_is_recovered_on_every_grid() {
        let ieee = [0.0, 1e-6, 0.0, 1e-10, 0.0];
        let tone = [(2e-5, 17.0)];
        for per_decade in [5.0, 10.0, 20.0, 50.0] {
            let taus = grid(per_decade, 0.01, 1000.0);
            let var = curve_with(&taus, &ieee, &[], (&tone, &[], &[]));
            let fit = fit_exact(&taus, &var);
            assert_eq!(fit.sine.len(), 1, "{per_decade}: {fit:?}");
            assert!(fit.gm.is_empty(), "{per_decade}: {fit:?}");
            let (s2, f0) = fit.sine[0];
            assert!((s2 / tone[0].0 - 1.0).abs() < 0.01, "{per_decade}: {s2}");
            assert!((f0 / tone[0].1 - 1.0).abs() < 1e-3, "{per_decade}: {f0}");
            assert!((fit.ieee[1] / ieee[1] - 1.0).abs() < 0.01);
            let u = fit.cov[SINE_SLOT][SINE_SLOT].sqrt();
            assert!(u.is_finite() && u < s2, "{per_decade}: {u}");
        }
    }

    #[test]
    fn two_tones_are_recovered_where_one_alone_would_not_pay() {
        // Lines at 0.2 and 3.3 Hz over white noise: each dominates its own
        // decade of taus, and the structure with one of them keeps the other's
        // misfit (the simulated parked-vehicle class of the fit's benchmark).
        let ieee = [0.0, 4e-10, 0.0, 0.0, 0.0];
        let tones = [(5e-9, 0.2), (4.5e-8, 3.3)];
        for per_decade in [10.0, 20.0] {
            let taus = grid(per_decade, 0.01, 180.0);
            let var = curve_with(&taus, &ieee, &[], (&tones, &[], &[]));
            let fit = fit_exact(&taus, &var);
            assert_eq!(fit.sine.len(), 2, "{per_decade}: {fit:?}");
            for (k, &(s2, f0)) in fit.sine.iter().enumerate() {
                assert!(
                    (s2 / tones[k].0 - 1.0).abs() < 0.01,
                    "{per_decade}: {fit:?}"
                );
                assert!(
                    (f0 / tones[k].1 - 1.0).abs() < 1e-3,
                    "{per_decade}: {fit:?}"
                );
                let u = fit.cov[SINE_SLOT + 2 * k][SINE_SLOT + 2 * k].sqrt();
                assert!(u.is_finite() && u < s2, "{per_decade}: {u}");
            }
            assert!((fit.ieee[1] / ieee[1] - 1.0).abs() < 0.01, "{fit:?}");
            let one = Options {
                tones: 1,
                ..Options::default()
            };
            let edf = vec![1e6; taus.len()];
            let single = fit_noise(&taus, &var, &edf, FS, &one, None).unwrap();
            assert!(
                single.sine.len() <= 1 && single.bic > fit.bic + 10.0,
                "{single:?}"
            );
        }
    }

    #[test]
    fn a_resonance_is_recovered_next_to_a_tone() {
        // A 10 Hz line and a band at 30 Hz (Q = π·30·0.02 ≈ 1.9), on white and
        // rate random walk noise: the VN-100 gyro's pattern at 100 Hz.
        let ieee = [0.0, 1e-6, 0.0, 1e-10, 0.0];
        let tone = [(2e-5, 10.0)];
        let res = [(4e-4, 30.0, 0.02, 0.0)];
        for per_decade in [10.0, 20.0] {
            let taus = grid(per_decade, 0.01, 1000.0);
            let var = curve_with(&taus, &ieee, &[], (&tone, &res, &[]));
            let fit = fit_exact(&taus, &var);
            assert_eq!(fit.resonance.len(), 1, "{per_decade}: {fit:?}");
            assert_eq!(fit.sine.len(), 1, "{per_decade}: {fit:?}");
            let (r2, f, tr, _) = fit.resonance[0];
            assert!((r2 / res[0].0 - 1.0).abs() < 0.02, "{per_decade}: {fit:?}");
            assert!((f / res[0].1 - 1.0).abs() < 0.01, "{per_decade}: {f}");
            assert!((tr / res[0].2 - 1.0).abs() < 0.02, "{per_decade}: {tr}");
            assert!((fit.sine[0].1 / tone[0].1 - 1.0).abs() < 1e-3);
            for s in RESONANCE_SLOT..RESONANCE_SLOT + 3 {
                assert!(fit.cov[s][s].is_finite() && fit.cov[s][s] > 0.0, "{s}");
            }
        }
    }

    #[test]
    fn a_second_order_filter_is_a_resonance_with_its_quadrature() {
        // A band of Q ½ at 7 Hz with the quadrature of a low-pass filter, a third
        // of the way to its bound, on white noise and rate random walk: the plain
        // resonance (skew 0) cannot draw it, the skewed one is recovered.
        let ieee = [0.0, 1e-6, 0.0, 1e-10, 0.0];
        let (f_r, tau_r) = (7.0, 0.5 / (std::f64::consts::PI * 7.0));
        let skew = 1.0 / 3.0;
        let res = [(4e-4, f_r, tau_r, skew)];
        for per_decade in [10.0, 20.0] {
            let taus = grid(per_decade, 0.01, 1000.0);
            let var = curve_with(&taus, &ieee, &[], (&[], &res, &[]));
            let fit = fit_exact(&taus, &var);
            assert_eq!(fit.resonance.len(), 1, "{per_decade}: {fit:?}");
            let (r2, f, tr, b) = fit.resonance[0];
            assert!((r2 / res[0].0 - 1.0).abs() < 0.02, "{per_decade}: {fit:?}");
            assert!((f / f_r - 1.0).abs() < 0.02, "{per_decade}: {f}");
            assert!((tr / tau_r - 1.0).abs() < 0.02, "{per_decade}: {tr}");
            assert!((b / skew - 1.0).abs() < 0.05, "{per_decade}: {b} vs {skew}");
            assert!(
                fit.cov[SKEW_SLOT][SKEW_SLOT] > 0.0,
                "{:?}",
                fit.cov[SKEW_SLOT]
            );
            assert!((fit.ieee[1] / ieee[1] - 1.0).abs() < 0.02, "{:?}", fit.ieee);
        }
    }

    #[test]
    fn tone_frequencies_stay_where_the_grid_resolves_them() {
        let dense = grid(10.0, 0.01, 1000.0);
        let data = Data::new(&dense, &vec![1.0; dense.len()], &vec![1e3; dense.len()], FS).unwrap();
        let f = search::frequency_grid(&data, FS);
        assert!(f[0] >= search::SINE_PERIODS / 1000.0, "{}", f[0]);
        assert_eq!(f[f.len() - 1], FS / 2.0);
        let sparse = grid(1.0, 0.01, 1000.0);
        let data = Data::new(
            &sparse,
            &vec![1.0; sparse.len()],
            &vec![1e3; sparse.len()],
            FS,
        )
        .unwrap();
        assert!(search::frequency_grid(&data, FS).is_empty());
    }

    #[test]
    fn white_noise_through_a_known_filter_is_white_noise_alone() {
        // A 4-tap moving average (a sensor's decimating FIR): with its gain the
        // fit needs no resonance, tone or Gauss–Markov term to draw the short taus.
        let gain: Vec<f64> = (0..257)
            .map(|k| {
                let nu = 0.5 * k as f64 / 256.0;
                let s = (std::f64::consts::PI * nu).sin();
                if s == 0.0 {
                    1.0
                } else {
                    ((4.0 * std::f64::consts::PI * nu).sin() / (4.0 * s)).powi(2)
                }
            })
            .collect();
        let filter = OutputFilter::new(gain).unwrap();
        let truth = [0.0, 4e-6, 1e-6, 1e-10, 0.0];
        let taus = grid(10.0, 0.01, 2000.0);
        let var: Vec<f64> = (terms(&taus, FS, &truth, &[], (&[], &[], &[]), Some(&filter)).iter())
            .map(|r| r.iter().sum())
            .collect();
        let edf = vec![1e6; taus.len()];
        let fit = fit_noise(&taus, &var, &edf, FS, &Options::default(), Some(&filter)).unwrap();
        assert!(
            fit.gm.is_empty() && fit.sine.is_empty() && fit.resonance.is_empty(),
            "{fit:?}"
        );
        assert!(
            (fit.ieee[1] / truth[1] - 1.0).abs() < 1e-3,
            "{:?}",
            fit.ieee
        );
        let blind = fit_noise(&taus, &var, &edf, FS, &Options::default(), None).unwrap();
        assert!(blind.bic > fit.bic, "{blind:?}");
    }

    #[test]
    fn covariance_shrinks_with_edf() {
        let truth = [0.0, 4e-6, 1e-6, 1e-10, 0.0];
        let taus = grid(5.0, 0.01, 2000.0);
        let mut var = curve(&taus, &truth, &[]);
        // A deterministic wiggle so the discrepancy is not exactly zero.
        for (i, v) in var.iter_mut().enumerate() {
            *v *= 1.0 + 1e-3 * ((i % 3) as f64 - 1.0);
        }
        let opts = Options {
            select: false,
            gm: 0,
            tones: 0,
            resonance: false,
            motion: false,
            ieee: [false, true, true, true, false],
        };
        let lo = fit_noise(&taus, &var, &edf_white(&taus, 1e4), FS, &opts, None).unwrap();
        let hi = fit_noise(&taus, &var, &edf_white(&taus, 1e6), FS, &opts, None).unwrap();
        for j in [1, 2, 3] {
            assert!(lo.cov[j][j] > hi.cov[j][j], "{j}");
        }
    }

    #[test]
    fn bad_inputs_are_errors_not_panics() {
        let o = Options::default();
        assert!(fit_noise(&[], &[], &[], FS, &o, None).is_err());
        assert!(fit_noise(&[1.0], &[1.0, 2.0], &[1.0], FS, &o, None).is_err());
        assert!(fit_noise(&[1.0, f64::NAN], &[1.0, 2.0], &[1.0, 1.0], FS, &o, None).is_err());
        assert!(fit_noise(&[1.0, 2.0], &[1.0, -2.0], &[1.0, 1.0], FS, &o, None).is_err());
        assert!(fit_noise(&[2.0, 1.0], &[1.0, 2.0], &[1.0, 1.0], FS, &o, None).is_err());
        assert!(fit_noise(&[1.0, 2.0], &[1.0, 2.0], &[0.0, 1.0], FS, &o, None).is_err());
        assert!(fit_noise(&[1.0, 2.0], &[1.0, 2.0], &[1.0, 1.0], 0.0, &o, None).is_err());
        let too_many = Options {
            gm: MAX_GM + 1,
            ..o
        };
        assert!(fit_noise(&[1.0, 2.0], &[1.0, 2.0], &[1.0, 1.0], FS, &too_many, None).is_err());
        let one = fit_noise(&[1.0], &[1.0], &[5.0], FS, &o, None).unwrap();
        assert!(one.ieee.iter().all(|c| c.is_finite() && *c >= 0.0));
    }
}
