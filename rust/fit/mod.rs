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

pub mod ambiguity;
pub mod basis;
pub mod datasheet;
pub mod estimate;
pub mod filter;
pub mod nnls;
pub mod oscillators;
pub mod search;
pub mod special;
pub mod term;

pub use basis::{FLICKER_FACTOR, IEEE_TERMS, IEEE_TERM_NAMES};
pub use term::{Kind, Term};

use crate::error::{CoreError, CoreResult};
use estimate::Data;
use filter::OutputFilter;
use search::Candidate;

/// Most Gauss–Markov terms a model may have.
pub const MAX_GM: usize = 3;

pub use search::MAX_TONES;

/// What [`fit_noise`] may use: how many terms of each kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Terms of each kind, indexed as [`Kind::ALL`]: the most the selection may
    /// use (`select`), or the number fitted; at most [`Kind::most`].
    pub counts: [usize; Kind::ALL.len()],
    /// Choose the structure by its score (`true`), or fit exactly the terms given.
    pub select: bool,
}

impl Options {
    /// Every kind of term up to its most, the structure selected.
    pub fn auto() -> Options {
        Options {
            counts: Kind::ALL.map(Kind::most),
            select: true,
        }
    }

    /// Exactly `kinds` (kind, count), nothing else, no selection.
    pub fn exactly(kinds: &[(Kind, usize)]) -> Options {
        let mut counts = [0; Kind::ALL.len()];
        for &(kind, n) in kinds {
            counts[kind as usize] += n;
        }
        Options {
            counts,
            select: false,
        }
    }

    /// How many terms of `kind`.
    pub fn count(&self, kind: Kind) -> usize {
        self.counts[kind as usize]
    }

    /// Which of Q, N, B, K, R may enter.
    pub fn ieee(&self) -> [bool; IEEE_TERMS] {
        Kind::IEEE.map(|k| self.count(k) > 0)
    }

    /// An error naming the first kind asked for more often than it may be.
    fn check(&self) -> CoreResult<()> {
        match Kind::ALL.into_iter().find(|&k| self.count(k) > k.most()) {
            Some(k) => Err(CoreError::InvalidArgument(format!(
                "at most {} {} term(s); got {}",
                k.most(),
                k.name(),
                self.count(k)
            ))),
            None => Ok(()),
        }
    }
}

impl Default for Options {
    fn default() -> Self {
        Options::auto()
    }
}

/// One channel's fitted model.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseFit {
    /// The terms of the chosen structure, each with variance > 0, in the order
    /// of [`Kind::ALL`]: the IEEE terms, then Gauss–Markov terms by increasing τc,
    /// tones by increasing frequency, the resonance, the bounded motion.
    pub terms: Vec<Term>,
    /// Covariance of the terms' coordinates ([`Kind::coordinate_names`]), term
    /// after term in the order of `terms`: the inverse Fisher information of the
    /// loss. A coordinate that is not free ([`Term::free`]) has variance NaN on a
    /// bound (a resonance at fs/2, a skew of ±1) and 0 where it is fixed (the skew
    /// of a plain resonance), and no covariance.
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
    /// Terms of a selected structure that an alternative fits as well
    /// ([`ambiguity::ambiguities`]): not resolved by the data. Empty for a
    /// structure fitted as requested.
    pub ambiguous: Vec<ambiguity::Ambiguity>,
}

impl NoiseFit {
    /// Where each term's block starts in [`NoiseFit::cov`].
    pub fn offsets(&self) -> Vec<usize> {
        offsets(&self.terms)
    }

    /// The terms of kind `kind`.
    pub fn of_kind(&self, kind: Kind) -> impl Iterator<Item = &Term> {
        self.terms.iter().filter(move |t| t.kind() == kind)
    }
}

/// Where each term's block of coordinates starts, term after term.
pub fn offsets(terms: &[Term]) -> Vec<usize> {
    let mut at = 0;
    terms
        .iter()
        .map(|t| {
            let start = at;
            at += t.kind().coordinate_names().len();
            start
        })
        .collect()
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
    opts.check()?;
    let (ieee, gm) = (opts.ieee(), opts.count(Kind::GaussMarkov));
    let reported = Data::new(taus, var, edf, fs)?.with_filter(filter);
    // The search and its pruning judge terms by what the data constrain.
    let data = reported.judged();
    let chosen = if opts.select {
        choose(&data, fs, opts)?
    } else {
        search::requested(&data, fs, opts)?
    };
    let mut fit = summarise(&reported, fs, &chosen);
    if opts.select {
        let without = |j: usize| without_term(&data, fs, opts, &chosen, j);
        fit.ambiguous = ambiguity::ambiguities(&data, fs, ieee, gm, &chosen, without);
    }
    Ok(fit)
}

/// One channel's model with the times and frequencies of `terms` held and their
/// variances fitted again to `taus`, `var`, `edf` (as [`fit_noise`]): a tone's
/// frequency confirmed by the spectrum replaces the Allan fit's own.
pub fn fit_noise_at(
    taus: &[f64],
    var: &[f64],
    edf: &[f64],
    fs: f64,
    terms: &[Term],
    filter: Option<&OutputFilter>,
) -> CoreResult<NoiseFit> {
    let reported = Data::new(taus, var, edf, fs)?.with_filter(filter);
    let held = search::held(&reported.judged(), fs, terms)?;
    Ok(summarise(&reported, fs, &held))
}

/// The best structure without IEEE term `j`: its IEEE and Gauss–Markov terms
/// selected again with `j` left out, alone and with `chosen`'s tones, resonance
/// and motion kept (their searches, most of the selection's time, are not
/// repeated: a structure that needs them has them from `chosen`). Its BIC decides.
fn without_term(
    data: &Data,
    fs: f64,
    opts: &Options,
    chosen: &Candidate,
    j: usize,
) -> Option<Candidate> {
    let mut ieee = opts.ieee();
    ieee[j] = false;
    let gm = opts.count(Kind::GaussMarkov);
    let plain = search::select(data, fs, ieee, gm, (0, false, false)).ok()?;
    let plain = prune_insignificant(data, fs, plain).ok()?;
    let extras = (chosen.sine, chosen.resonance, chosen.motion);
    let (times, d2) = (plain.gm_in_use(), plain.solution.d2);
    let kept = search::candidate(data, fs, plain.ieee, times, extras, d2).ok();
    Some(match kept {
        Some(k) if k.bic < plain.bic => k,
        _ => plain,
    })
}

/// The structure the selection chooses among the kinds of terms `opts` allows.
fn choose(data: &Data, fs: f64, opts: &Options) -> CoreResult<Candidate> {
    let (ieee, gm) = (opts.ieee(), opts.count(Kind::GaussMarkov));
    let selected = |motion: bool| -> CoreResult<Candidate> {
        let kinds = (
            opts.count(Kind::Tone),
            opts.count(Kind::Resonance) > 0,
            motion,
        );
        let best = search::select(data, fs, ieee, gm, kinds)?;
        let best = search::prefer_random_walk(data, fs, ieee, gm, kinds, best)?;
        prune_insignificant(data, fs, best)
    };
    let best = selected(opts.count(Kind::Motion) > 0)?;
    // A motion is searched last, on what the search had then; pruning and the
    // walk's check after it can leave a structure the search without it beats.
    // It stays only if it wins.
    if best.motion.is_some() {
        let without = selected(false)?;
        if without.score() <= best.score() {
            return Ok(without);
        }
    }
    Ok(best)
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
    // two free removals can pay for a costly third (K and R, nearly collinear
    // with B at the longest taus, would take B with them).
    let allowance = PRUNE_PENALTIES * data.n_eff().max(2.0).ln();
    let selected = best.solution.loss;
    let mut removed = 0.0;
    'outer: loop {
        let fit = summarise(data, fs, &best);
        if fit.terms.len() <= 1 {
            return Ok(best);
        }
        let offsets = fit.offsets();
        // What may go: a term (its index), or a resonance's quadrature part.
        #[derive(Clone, Copy)]
        enum Removal {
            Term(usize),
            Quadrature,
        }
        let z = |slot: usize, v: f64| v / fit.cov[slot][slot].sqrt();
        let weak = |candidates: Vec<(Removal, f64)>| {
            let mut out: Vec<(Removal, f64)> = candidates
                .into_iter()
                .filter(|(_, z)| z.is_finite() && *z < MIN_Z)
                .collect();
            out.sort_by(|a, b| a.1.total_cmp(&b.1));
            out
        };
        let indexed = |pick: &dyn Fn(Kind) -> bool| -> Vec<(Removal, f64)> {
            (fit.terms.iter().enumerate())
                .filter(|(_, t)| pick(t.kind()))
                .map(|(k, t)| (Removal::Term(k), z(offsets[k], t.variance())))
                .collect()
        };
        // A quadrature part the data do not constrain: the plain resonance.
        let quadrature = (fit.terms.iter().enumerate()).filter_map(|(k, t)| match *t {
            Term::Resonance { skew, .. } if skew != 0.0 => {
                Some((Removal::Quadrature, z(offsets[k] + 3, skew.abs())))
            }
            _ => None,
        });
        let oscillating = |k: Kind| matches!(k, Kind::Tone | Kind::Resonance | Kind::Motion);
        let mut order = weak(quadrature.chain(indexed(&oscillating)).collect());
        order.extend(weak(indexed(&|k| k == Kind::GaussMarkov)));
        order.extend(weak(indexed(&|k| Kind::IEEE.contains(&k))));
        for (removal, _) in order {
            let mut ieee = best.ieee;
            let kept: Vec<(usize, &Term)> = (fit.terms.iter().enumerate())
                .filter(|(k, _)| !matches!(removal, Removal::Term(r) if r == *k))
                .collect();
            let times: Vec<f64> = (kept.iter())
                .filter_map(|(_, t)| match t {
                    Term::GaussMarkov { tau_c, .. } => Some(*tau_c),
                    _ => None,
                })
                .collect();
            let tones: Vec<f64> = (kept.iter())
                .filter_map(|(_, t)| match t {
                    Term::Tone { freq, .. } => Some(*freq),
                    _ => None,
                })
                .collect();
            let mut resonance = best
                .resonance
                .filter(|_| kept.iter().any(|(_, t)| t.kind() == Kind::Resonance));
            if let Removal::Quadrature = removal {
                resonance = resonance.map(|r| search::Resonance { skewed: false, ..r });
            }
            let motion = kept.iter().find_map(|(_, t)| match t {
                Term::Motion { tau_c, .. } => Some(*tau_c),
                _ => None,
            });
            if let Removal::Term(k) = removal {
                if let Some(j) = Kind::IEEE.iter().position(|&i| i == fit.terms[k].kind()) {
                    ieee[j] = false;
                }
            }
            let extras = (search::Tones::from_slice(&tones), resonance, motion);
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
    let terms = c.terms(fs);
    let chi2 = (0..data.len())
        .map(|i| data.omega[i] * (data.y[i] - c.solution.model[i].ln()).powi(2) / data.v[i])
        .sum();
    NoiseFit {
        cov: covariance(data, fs, &terms, c.solution.d2),
        terms,
        discrepancy: c.solution.d2.sqrt(),
        chi2,
        n_eff: data.n_eff(),
        parameters: search::parameters(&c.solution.theta, c.resonance, c.motion.is_some()),
        bic: c.bic,
        ambiguous: Vec::new(),
    }
}

/// Model Allan variance of each term at `taus`: row i holds one value per term
/// of `terms`, in their order. The white term is seen through `filter`, if given.
pub fn allan_terms(
    taus: &[f64],
    fs: f64,
    terms: &[Term],
    filter: Option<&OutputFilter>,
) -> Vec<Vec<f64>> {
    let ms: Vec<f64> = taus.iter().map(|t| t * fs).collect();
    let white = filter.map_or_else(|| vec![1.0; taus.len()], |f| f.white_factors(&ms));
    (taus.iter().zip(&white))
        .map(|(&t, &white)| {
            (terms.iter())
                .map(|term| term.allan_variance(t, t * fs, fs, white))
                .collect()
        })
        .collect()
}

/// The model's Allan variance at tau `i` of `data`: the terms summed by kind
/// group (IEEE, Gauss–Markov, tones, resonance, motion), the groups then in turn.
fn model_at(data: &Data, fs: f64, terms: &[Term], i: usize) -> f64 {
    let mut groups = [0.0; 5];
    for term in terms {
        let group = match term.kind() {
            Kind::GaussMarkov => 1,
            Kind::Tone => 2,
            Kind::Resonance => 3,
            Kind::Motion => 4,
            _ => 0,
        };
        groups[group] += term.allan_variance(data.taus[i], data.m[i], fs, data.white[i]);
    }
    groups.iter().sum()
}

/// Inverse Fisher information of the loss at the solution, over the terms'
/// coordinates ([`NoiseFit::cov`]).
fn covariance(data: &Data, fs: f64, terms: &[Term], d2: f64) -> Vec<Vec<f64>> {
    let starts = offsets(terms);
    let size = terms
        .iter()
        .map(|t| t.kind().coordinate_names().len())
        .sum();
    // The free coordinates and, per tau, ∂ ln M/∂ each.
    let mut slots: Vec<usize> = Vec::new();
    // A resonance's frequency and skew: near fs/2 nearly unidentified (its curve
    // is even in f_r − fs/2 there, and the quadrature part vanishes), so the
    // information can be singular in them; they are then left out (NaN).
    let mut weakly_identified: Vec<usize> = Vec::new();
    for (k, term) in terms.iter().enumerate() {
        for (j, free) in term.free(fs).into_iter().enumerate() {
            if free {
                slots.push(starts[k] + j);
            }
            if term.kind() == Kind::Resonance && (j == 1 || j == 3) {
                weakly_identified.push(starts[k] + j);
            }
        }
    }
    let rows: Vec<(f64, Vec<f64>)> = (0..data.len())
        .map(|i| {
            let model = model_at(data, fs, terms, i);
            let mut grad = vec![0.0; size];
            for (k, term) in terms.iter().enumerate() {
                let g = term.gradient(data.taus[i], data.m[i], fs, data.white[i]);
                grad[starts[k]..starts[k] + g.len()].copy_from_slice(&g);
            }
            let grad = slots.iter().map(|&s| grad[s] / model).collect();
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
    let all: Vec<usize> = (0..slots.len()).collect();
    let without_oscillator: Vec<usize> = (0..slots.len())
        .filter(|&a| !weakly_identified.contains(&slots[a]))
        .collect();
    let mut cov = vec![vec![0.0; size]; size];
    for (k, term) in terms.iter().enumerate() {
        for (j, free) in term.free(fs).into_iter().enumerate() {
            // On a bound: NaN. The plain resonance's skew is fixed at 0: variance 0.
            let fixed = matches!(term, Term::Resonance { skew, .. } if j == 3 && *skew == 0.0);
            if free || !fixed {
                cov[starts[k] + j][starts[k] + j] = f64::NAN;
            }
        }
    }
    // The output filter's white level, measured with a relative variance: the fitted
    // coordinates move with it by dx/dε = −F⁻¹ Σ wᵢ gᵢ hᵢ, hᵢ = ∂ln Mᵢ/∂ε (the white
    // term's share through the level's slope of c), and carry that variance too.
    let level: Vec<f64> = (0..data.len())
        .filter(|_| data.level_var > 0.0)
        .map(|i| {
            let white: f64 = (terms.iter())
                .filter(|t| t.kind() == Kind::White)
                .map(|t| t.allan_variance(data.taus[i], data.m[i], fs, data.white_level[i]))
                .sum();
            white / model_at(data, fs, terms, i)
        })
        .collect();
    for keep in [all, without_oscillator] {
        if let Some(inv) = nnls::invert_spd(&fisher(&keep)) {
            let pull: Vec<f64> = (keep.iter())
                .filter(|_| data.level_var > 0.0)
                .map(|&a| {
                    (rows.iter().zip(&level))
                        .map(|((w, g), h)| w * g[a] * h)
                        .sum()
                })
                .collect();
            let moved: Vec<f64> = (0..pull.len())
                .map(|a| -(0..keep.len()).map(|b| inv[a][b] * pull[b]).sum::<f64>())
                .collect();
            for (a, &ka) in keep.iter().enumerate() {
                for (b, &kb) in keep.iter().enumerate() {
                    cov[slots[ka]][slots[kb]] = inv[a][b];
                    if data.level_var > 0.0 {
                        cov[slots[ka]][slots[kb]] += data.level_var * moved[a] * moved[b];
                    }
                }
            }
            break;
        }
    }
    cov
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tone (s², f₀), resonance (r², f_r, τr, skew) and bounded motion
    /// (σθ², τc) terms of a test model.
    type Oscillators<'a> = (
        &'a [(f64, f64)],
        &'a [(f64, f64, f64, f64)],
        &'a [(f64, f64)],
    );

    /// The typed terms of a model given as the five IEEE variances, (q², τc)
    /// pairs and oscillators.
    fn typed(ieee: &[f64; 5], gm: &[(f64, f64)], (sine, res, motion): Oscillators) -> Vec<Term> {
        let mut t: Vec<Term> = (0..IEEE_TERMS)
            .filter(|&j| ieee[j] > 0.0)
            .map(|j| Term::ieee(j, ieee[j]))
            .collect();
        t.extend(
            gm.iter()
                .map(|&(variance, tau_c)| Term::GaussMarkov { variance, tau_c }),
        );
        t.extend(
            sine.iter()
                .map(|&(variance, freq)| Term::Tone { variance, freq }),
        );
        t.extend(
            res.iter()
                .map(|&(variance, freq, tau, skew)| Term::Resonance {
                    variance,
                    freq,
                    tau,
                    skew,
                }),
        );
        t.extend(
            motion
                .iter()
                .map(|&(variance, tau_c)| Term::Motion { variance, tau_c }),
        );
        t
    }

    /// A fit's terms read back as plain tuples, and the variances of their
    /// coordinates.
    trait Read {
        fn ieee(&self) -> [f64; 5];
        fn gm(&self) -> Vec<(f64, f64)>;
        fn sine(&self) -> Vec<(f64, f64)>;
        fn resonance(&self) -> Vec<(f64, f64, f64, f64)>;
        /// Variance of coordinate `j` of the `k`-th term of kind `kind`.
        fn var(&self, kind: Kind, k: usize, j: usize) -> f64;
    }

    impl Read for NoiseFit {
        fn ieee(&self) -> [f64; 5] {
            let mut out = [0.0; 5];
            for t in &self.terms {
                if let Some(j) = Kind::IEEE.iter().position(|&k| k == t.kind()) {
                    out[j] = t.variance();
                }
            }
            out
        }
        fn gm(&self) -> Vec<(f64, f64)> {
            (self.of_kind(Kind::GaussMarkov))
                .map(|t| (t.parameters()[0], t.parameters()[1]))
                .collect()
        }
        fn sine(&self) -> Vec<(f64, f64)> {
            (self.of_kind(Kind::Tone))
                .map(|t| (t.parameters()[0], t.parameters()[1]))
                .collect()
        }
        fn resonance(&self) -> Vec<(f64, f64, f64, f64)> {
            (self.of_kind(Kind::Resonance))
                .map(|t| {
                    let p = t.parameters();
                    (p[0], p[1], p[2], p[3])
                })
                .collect()
        }
        fn var(&self, kind: Kind, k: usize, j: usize) -> f64 {
            let index = (self.terms.iter().enumerate())
                .filter(|(_, t)| t.kind() == kind)
                .nth(k)
                .map(|(i, _)| i)
                .unwrap();
            let at = self.offsets()[index] + j;
            self.cov[at][at]
        }
    }

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
        allan_terms(taus, FS, &typed(ieee, gm, oscillators), None)
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
        assert!(fit.gm().is_empty(), "{:?}", fit.gm());
        assert!(fit.sine().is_empty(), "{:?}", fit.sine());
        assert!(fit.resonance().is_empty(), "{:?}", fit.resonance());
        for j in [1, 2, 3] {
            assert!(
                (fit.ieee()[j] / truth[j] - 1.0).abs() < 1e-3,
                "{j}: {:?}",
                fit.ieee()
            );
        }
        assert_eq!(fit.ieee()[0], 0.0);
        assert_eq!(fit.ieee()[4], 0.0);
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
            assert_eq!(fit.gm().len(), 2, "{per_decade}: {fit:?}");
            assert!(fit.sine().is_empty(), "{per_decade}: {fit:?}");
            assert!(fit.resonance().is_empty(), "{per_decade}: {fit:?}");
            for (got, want) in fit.gm().iter().zip(truth_gm) {
                assert!(
                    (got.0 / want.0 - 1.0).abs() < 0.01,
                    "{per_decade}: {got:?} vs {want:?}"
                );
                assert!(
                    (got.1 / want.1 - 1.0).abs() < 0.01,
                    "{per_decade}: {got:?} vs {want:?}"
                );
            }
            assert!((fit.ieee()[1] / ieee[1] - 1.0).abs() < 0.01);
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
            assert_eq!(fit.sine().len(), 1, "{per_decade}: {fit:?}");
            assert!(fit.gm().is_empty(), "{per_decade}: {fit:?}");
            let (s2, f0) = fit.sine()[0];
            assert!((s2 / tone[0].0 - 1.0).abs() < 0.01, "{per_decade}: {s2}");
            assert!((f0 / tone[0].1 - 1.0).abs() < 1e-3, "{per_decade}: {f0}");
            assert!((fit.ieee()[1] / ieee[1] - 1.0).abs() < 0.01);
            let u = fit.var(Kind::Tone, 0, 0).sqrt();
            assert!(u.is_finite() && u < s2, "{per_decade}: {u}");
        }
    }

    #[test]
    fn held_terms_keep_their_frequencies_and_refit_their_variances() {
        let ieee = [0.0, 1e-6, 0.0, 1e-10, 0.0];
        let taus = grid(20.0, 0.01, 1000.0);
        let edf = vec![1e6; taus.len()];
        let var = curve_with(&taus, &ieee, &[], (&[(2e-5, 17.0)], &[], &[]));
        // the truth's structure with its variances wrong: fitted back to the truth
        let guess = typed(&[0.0, 1.0, 0.0, 1.0, 0.0], &[], (&[(1.0, 17.0)], &[], &[]));
        let fit = fit_noise_at(&taus, &var, &edf, FS, &guess, None).unwrap();
        assert!((fit.ieee()[1] / ieee[1] - 1.0).abs() < 1e-3, "{fit:?}");
        assert!((fit.sine()[0].0 / 2e-5 - 1.0).abs() < 1e-3, "{fit:?}");
        assert!(fit.ambiguous.is_empty());
        // a frequency given is kept, the variances follow it
        let moved = typed(&[0.0, 1.0, 0.0, 1.0, 0.0], &[], (&[(1.0, 17.5)], &[], &[]));
        let fit = fit_noise_at(&taus, &var, &edf, FS, &moved, None).unwrap();
        assert_eq!(fit.sine()[0].1, 17.5);
        let three = typed(
            &ieee,
            &[],
            (&[(1.0, 1.0), (1.0, 2.0), (1.0, 3.0)], &[], &[]),
        );
        assert!(fit_noise_at(&taus, &var, &edf, FS, &three, None).is_err());
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
            assert_eq!(fit.sine().len(), 2, "{per_decade}: {fit:?}");
            for (k, &(s2, f0)) in fit.sine().iter().enumerate() {
                assert!(
                    (s2 / tones[k].0 - 1.0).abs() < 0.01,
                    "{per_decade}: {fit:?}"
                );
                assert!(
                    (f0 / tones[k].1 - 1.0).abs() < 1e-3,
                    "{per_decade}: {fit:?}"
                );
                let u = fit.var(Kind::Tone, k, 0).sqrt();
                assert!(u.is_finite() && u < s2, "{per_decade}: {u}");
            }
            assert!((fit.ieee()[1] / ieee[1] - 1.0).abs() < 0.01, "{fit:?}");
            let mut one = Options::auto();
            one.counts[Kind::Tone as usize] = 1;
            let edf = vec![1e6; taus.len()];
            let single = fit_noise(&taus, &var, &edf, FS, &one, None).unwrap();
            assert!(
                single.sine().len() <= 1 && single.bic > fit.bic + 10.0,
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
            assert_eq!(fit.resonance().len(), 1, "{per_decade}: {fit:?}");
            assert_eq!(fit.sine().len(), 1, "{per_decade}: {fit:?}");
            let (r2, f, tr, _) = fit.resonance()[0];
            assert!((r2 / res[0].0 - 1.0).abs() < 0.02, "{per_decade}: {fit:?}");
            assert!((f / res[0].1 - 1.0).abs() < 0.01, "{per_decade}: {f}");
            assert!((tr / res[0].2 - 1.0).abs() < 0.02, "{per_decade}: {tr}");
            assert!((fit.sine()[0].1 / tone[0].1 - 1.0).abs() < 1e-3);
            for j in 0..3 {
                let v = fit.var(Kind::Resonance, 0, j);
                assert!(v.is_finite() && v > 0.0, "{j}");
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
            assert_eq!(fit.resonance().len(), 1, "{per_decade}: {fit:?}");
            let (r2, f, tr, b) = fit.resonance()[0];
            assert!((r2 / res[0].0 - 1.0).abs() < 0.02, "{per_decade}: {fit:?}");
            assert!((f / f_r - 1.0).abs() < 0.02, "{per_decade}: {f}");
            assert!((tr / tau_r - 1.0).abs() < 0.02, "{per_decade}: {tr}");
            assert!((b / skew - 1.0).abs() < 0.05, "{per_decade}: {b} vs {skew}");
            assert!(fit.var(Kind::Resonance, 0, 3) > 0.0, "{:?}", fit.cov);
            assert!(
                (fit.ieee()[1] / ieee[1] - 1.0).abs() < 0.02,
                "{:?}",
                fit.ieee()
            );
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
        let var: Vec<f64> = (allan_terms(
            &taus,
            FS,
            &typed(&truth, &[], (&[], &[], &[])),
            Some(&filter),
        )
        .iter())
        .map(|r| r.iter().sum())
        .collect();
        let edf = vec![1e6; taus.len()];
        let fit = fit_noise(&taus, &var, &edf, FS, &Options::default(), Some(&filter)).unwrap();
        assert!(
            fit.gm().is_empty() && fit.sine().is_empty() && fit.resonance().is_empty(),
            "{fit:?}"
        );
        assert!(
            (fit.ieee()[1] / truth[1] - 1.0).abs() < 1e-3,
            "{:?}",
            fit.ieee()
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
        let opts = Options::exactly(&[(Kind::White, 1), (Kind::Flicker, 1), (Kind::RandomWalk, 1)]);
        let lo = fit_noise(&taus, &var, &edf_white(&taus, 1e4), FS, &opts, None).unwrap();
        let hi = fit_noise(&taus, &var, &edf_white(&taus, 1e6), FS, &opts, None).unwrap();
        for j in [1, 2, 3] {
            assert!(lo.cov[j - 1][j - 1] > hi.cov[j - 1][j - 1], "{j}");
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
        let mut too_many = o;
        too_many.counts[Kind::GaussMarkov as usize] = MAX_GM + 1;
        assert!(fit_noise(&[1.0, 2.0], &[1.0, 2.0], &[1.0, 1.0], FS, &too_many, None).is_err());
        let one = fit_noise(&[1.0], &[1.0], &[5.0], FS, &o, None).unwrap();
        assert!(one.ieee().iter().all(|c| c.is_finite() && *c >= 0.0));
    }
}
