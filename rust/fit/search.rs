//! Model structure: the Gauss–Markov correlation times and the terms kept.
//!
//! Every term is linear in its variance once the correlation times are fixed,
//! so the fit is a variable projection: the loss as a function of the times
//! alone is minimised by a grid over log τc (6 per decade, anchored at 1 s so
//! the candidates do not depend on the tau grid) followed by golden-section
//! refinement of each time in turn; no nonlinear optimiser from a random start.
//!
//! Model selection ("auto"): for 0 to 3 Gauss–Markov terms, the full model
//! is fitted, then IEEE terms are removed one at a time while that lowers the
//! Bayesian information criterion BIC = L + p·ln(n_eff), with L the loss at its
//! joint minimum (−2 log-likelihood), p the number of non-zero variance
//! parameters plus one per correlation time, and n_eff = Σω the number of
//! octaves of evidence. The structure with the lowest BIC is kept.

use faer::Mat;

use super::basis::{self, IEEE_TERMS};
use super::estimate::{self, Data, Solution};
use crate::error::CoreResult;

/// Grid of candidate correlation times per decade.
const PER_DECADE: f64 = 6.0;

/// Smallest ratio between the correlation times of two Gauss–Markov terms.
const MIN_RATIO: f64 = 2.0;

/// The basis of a structure: IEEE columns, then one column per GM time.
pub fn design(data: &Data, fs: f64, gm_tau: &[f64]) -> Mat<f64> {
    let k = IEEE_TERMS + gm_tau.len();
    Mat::from_fn(data.len(), k, |i, j| {
        if j < IEEE_TERMS {
            basis::ieee(data.taus[i])[j]
        } else {
            basis::gauss_markov(data.m[i], basis::gm_rate(gm_tau[j - IEEE_TERMS], fs))
        }
    })
}

fn allowed_with_gm(ieee: &[bool; IEEE_TERMS], gm: usize) -> Vec<bool> {
    let mut a = ieee.to_vec();
    a.extend(std::iter::repeat_n(true, gm));
    a
}

/// Candidate correlation times: 10^(j/6) s from half a sample (φ = e⁻² ≈ 0.14;
/// faster is white noise to any cluster size) to three times the longest tau.
pub fn time_grid(data: &Data, fs: f64) -> Vec<f64> {
    let lo = (0.5 / fs).log10();
    let hi = (3.0 * data.taus[data.len() - 1]).log10();
    let (a, b) = (
        (lo * PER_DECADE).ceil() as i64,
        (hi * PER_DECADE).floor() as i64,
    );
    (a..=b).map(|j| 10f64.powf(j as f64 / PER_DECADE)).collect()
}

struct Searcher<'a> {
    data: &'a Data,
    fs: f64,
    ieee: [bool; IEEE_TERMS],
    d2: f64,
}

impl Searcher<'_> {
    /// Loss of the best θ for these times at the searcher's fixed δ².
    fn loss(&self, times: &[f64]) -> f64 {
        let basis = design(self.data, self.fs, times);
        let allowed = allowed_with_gm(&self.ieee, times.len());
        match estimate::solve_theta(
            estimate::Problem {
                data: self.data,
                basis: &basis,
                allowed: &allowed,
            },
            self.d2,
            None,
            8,
        ) {
            Ok((_, model)) => estimate::loss(self.data, &model, self.d2),
            Err(_) => f64::INFINITY,
        }
    }

    /// Golden-section search of time `which` in [lo, hi] (others fixed).
    fn refine(&self, times: &mut [f64], which: usize, lo: f64, hi: f64) {
        let g = 0.5 * (5f64.sqrt() - 1.0);
        let (mut a, mut b) = (lo.ln(), hi.ln());
        let at = |x: f64, times: &mut [f64]| {
            times[which] = x.exp();
            self.loss(times)
        };
        let best_start = (times[which].ln(), self.loss(times));
        let mut c = b - g * (b - a);
        let mut d = a + g * (b - a);
        let mut fc = at(c, times);
        let mut fd = at(d, times);
        while b - a > 1e-2 {
            if fc < fd {
                b = d;
                d = c;
                fd = fc;
                c = b - g * (b - a);
                fc = at(c, times);
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + g * (b - a);
                fd = at(d, times);
            }
        }
        let (x, f) = if fc < fd { (c, fc) } else { (d, fd) };
        times[which] = if f <= best_start.1 { x } else { best_start.0 }.exp();
    }

    /// Best `count` correlation times (ascending); for three, `seed` is the best
    /// pair found before (searched again when empty).
    fn times(&self, count: usize, seed: &[f64]) -> Vec<f64> {
        let grid = time_grid(self.data, self.fs);
        if count == 0 || grid.len() < count {
            return Vec::new();
        }
        let step = 10f64.powf(1.0 / PER_DECADE);
        let best_of = |cands: Vec<Vec<f64>>| -> Vec<f64> {
            cands
                .into_iter()
                .map(|t| (self.loss(&t), t))
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .map(|(_, t)| t)
                .unwrap_or_default()
        };
        let mut times = match count {
            1 => best_of(grid.iter().map(|&t| vec![t]).collect()),
            2 => {
                // Pairs on every third grid point (two per decade); the
                // refinement below then searches ± a half decade around each.
                let coarse: Vec<f64> = grid.iter().copied().step_by(3).collect();
                let mut pairs = Vec::new();
                for i in 0..coarse.len() {
                    for j in (i + 1)..coarse.len() {
                        pairs.push(vec![coarse[i], coarse[j]]);
                    }
                }
                best_of(pairs)
            }
            _ => {
                // One more time, scanned over the grid around the best smaller set.
                let base = if seed.len() == count - 1 {
                    seed.to_vec()
                } else {
                    self.times(count - 1, &[])
                };
                let free = grid
                    .iter()
                    .filter(|&&t| base.iter().all(|&b| (t / b).max(b / t) >= MIN_RATIO))
                    .map(|&t| {
                        let mut v = base.clone();
                        v.push(t);
                        v.sort_by(f64::total_cmp);
                        v
                    })
                    .collect();
                best_of(free)
            }
        };
        let span = if count == 2 { step * step * step } else { step };
        for _round in 0..2 {
            for which in 0..times.len() {
                let mut lo = times[which] / span;
                let mut hi = times[which] * span;
                // Two terms closer than a factor of 2 in τc are one term.
                if which > 0 {
                    lo = lo.max(times[which - 1] * MIN_RATIO);
                }
                if which + 1 < times.len() {
                    hi = hi.min(times[which + 1] / MIN_RATIO);
                }
                if lo < hi {
                    self.refine(&mut times, which, lo, hi);
                }
            }
        }
        times
    }
}

/// A fitted structure: its times, which IEEE terms were allowed, the solution
/// and its information criterion.
#[derive(Debug, Clone)]
pub struct Candidate {
    pub gm_tau: Vec<f64>,
    pub ieee: [bool; IEEE_TERMS],
    pub solution: Solution,
    pub bic: f64,
}

/// Number of free parameters of a solution: non-zero variances, and a time
/// for every Gauss–Markov term in use.
pub fn parameters(theta: &[f64]) -> usize {
    let used = theta.iter().filter(|t| **t > 0.0).count();
    let times = theta[IEEE_TERMS..].iter().filter(|t| **t > 0.0).count();
    used + times
}

/// Fit a structure with given correlation times (no search).
pub fn candidate(
    data: &Data,
    fs: f64,
    ieee: [bool; IEEE_TERMS],
    gm_tau: Vec<f64>,
    d2: f64,
) -> CoreResult<Candidate> {
    let basis = design(data, fs, &gm_tau);
    let allowed = allowed_with_gm(&ieee, gm_tau.len());
    let solution = estimate::solve_joint(
        estimate::Problem {
            data,
            basis: &basis,
            allowed: &allowed,
        },
        d2,
        None,
    )?;
    let bic = solution.loss + parameters(&solution.theta) as f64 * data.n_eff().max(2.0).ln();
    Ok(Candidate {
        gm_tau,
        ieee,
        solution,
        bic,
    })
}

/// Fit `gm` Gauss–Markov terms with the IEEE terms `ieee` (times searched;
/// `seed`: the best times of `gm − 1` terms, to extend).
pub fn fit_structure(
    data: &Data,
    fs: f64,
    ieee: [bool; IEEE_TERMS],
    gm: usize,
    d2: f64,
    seed: &[f64],
) -> CoreResult<Candidate> {
    let searcher = Searcher { data, fs, ieee, d2 };
    let times = searcher.times(gm, seed);
    let first = candidate(data, fs, ieee, times, d2)?;
    let settled = first.solution.d2;
    if gm == 0 || (settled <= 2.0 * d2 && settled >= 0.5 * d2) {
        return Ok(first);
    }
    // Search again at the discrepancy this structure settles on.
    let again = Searcher {
        d2: settled,
        ..searcher
    };
    let times = again.times(gm, seed);
    let second = candidate(data, fs, ieee, times, first.solution.d2)?;
    Ok(if second.solution.loss < first.solution.loss {
        second
    } else {
        first
    })
}

/// Backward elimination of IEEE terms while the BIC decreases.
fn eliminate(data: &Data, fs: f64, mut best: Candidate) -> CoreResult<Candidate> {
    loop {
        let active: Vec<usize> = (0..IEEE_TERMS)
            .filter(|&j| best.ieee[j] && best.solution.theta[j] > 0.0)
            .collect();
        let mut improved: Option<Candidate> = None;
        for j in active {
            let mut ieee = best.ieee;
            ieee[j] = false;
            let trial = candidate(data, fs, ieee, best.gm_tau.clone(), best.solution.d2)?;
            let bar = improved.as_ref().map_or(best.bic, |c| c.bic);
            if trial.bic < bar {
                improved = Some(trial);
            }
        }
        match improved {
            Some(c) => best = c,
            None => return Ok(best),
        }
    }
}

/// Automatic selection over 0..=`max_gm` Gauss–Markov terms and the IEEE terms
/// in `ieee`.
pub fn select(
    data: &Data,
    fs: f64,
    ieee: [bool; IEEE_TERMS],
    max_gm: usize,
) -> CoreResult<Candidate> {
    let base = fit_structure(data, fs, ieee, 0, 0.0, &[])?;
    let mut best = eliminate(data, fs, base.clone())?;
    let mut seed: Vec<f64> = Vec::new();
    for gm in 1..=max_gm {
        let full = fit_structure(data, fs, ieee, gm, base.solution.d2, &seed)?;
        seed = full.gm_tau.clone();
        let reduced = eliminate(data, fs, full)?;
        if reduced.bic < best.bic {
            best = reduced;
        }
    }
    Ok(best)
}
