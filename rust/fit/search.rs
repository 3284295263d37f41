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
//! octaves of evidence. The structure with the lowest BIC is kept, each
//! component beyond the IEEE terms (Gauss–Markov, tone, resonance) asked for
//! [`COMPONENT_EVIDENCE`] more.
//!
//! A sinusoid (a tone: a sensor's dither, a fan, a supply ripple) is one more
//! column, linear in its variance for a fixed frequency: the frequency is found
//! by a grid of [`FREQ_PER_DECADE`] per decade from [`SINE_PERIODS`] periods
//! in the longest tau to fs/2, a finer scan and golden-section refinement, the
//! Gauss–Markov times are then refined with the tone in place, and the toned
//! structure competes by the same BIC (two parameters: variance, frequency).
//!
//! A resonance (a damped oscillator: a sensor's filter top or a mechanical mode,
//! `basis::resonance`) is one more column, linear in its variance for a fixed
//! frequency f_r and damping time τr: a grid of [`RES_PER_DECADE`] frequencies
//! per decade from fs/[`RES_LOWEST`] to fs/2 times the quality factors [`RES_Q`]
//! (Q = πf_rτr, the centre frequency over the half-power bandwidth), then
//! Nelder–Mead in ln f_r and ln τr, the times polished and the tones searched
//! again with it in place; it competes by BIC with three parameters. A skewed
//! resonance (a second-order filter's shape, `basis::skewed_resonance`) is two
//! columns, the edges of its skew's cone, searched the same way beside every
//! plain one with one parameter more.
//! It is tried on the best structure found without it (tone or not), and a tone
//! is then searched again on top of it: a line and a band next to each other
//! are two terms.
//!
//! A bounded motion (`basis::motion`: the mount's angle wandering and coming
//! back, a parked vehicle's rocking) is one more column, linear in the angle's
//! variance for a fixed correlation time, searched last on the grid of
//! correlation times and refined like them; it competes by BIC with two
//! parameters. White below its correlation time and falling as 1/τ beyond, it
//! is what no other term draws: a −½ slope that steepens to −1.

use faer::Mat;

use super::basis::{self, IEEE_TERMS};
use super::estimate::{self, Data, Solution};
pub use super::oscillators::{Resonance, Tones, MAX_TONES};
use super::term::{Kind, Term};
use super::Options;
use crate::error::{CoreError, CoreResult};

/// Grid of candidate correlation times per decade.
const PER_DECADE: f64 = 6.0;

/// Smallest ratio between the correlation times of two Gauss–Markov terms.
const MIN_RATIO: f64 = 2.0;

/// Grid of candidate tone frequencies per decade: 2.4 % apart, so the grid point
/// next to a tone is within a quarter radian of its phase πf₀τ up to τ ≈ 6/f₀,
/// well past the tone's peak; the fine scan then resolves the longer taus.
const FREQ_PER_DECADE: f64 = 96.0;

/// A tone refined below this multiple of the frequency grid's lowest point (two
/// grid steps) is on the grid's bound.
const SINE_BOUND: f64 = 1.049;

/// Most steps of the fine frequency scan around the best grid point.
const FINE_SCAN: f64 = 100.0;

/// Golden-section tolerances in ln τc and ln f₀: a correlation time to 1 %; a
/// frequency to 10⁻⁷, since its phase πf₀τ at long τ depends on it.
const TIME_TOL: f64 = 1e-2;
const FREQ_TOL: f64 = 1e-7;

/// Grid of candidate resonance frequencies per decade (7 % apart, about half
/// the half-power width of the sharpest grid quality factor).
const RES_PER_DECADE: f64 = 32.0;

/// Lowest resonance frequency, as a fraction of fs: fs/20, a period of 20
/// samples. What the term is for — a sensor filter's top, a mechanical mode
/// near the sample rate — shapes the first few cluster sizes, where one tone
/// or Gauss–Markov term cannot; slower oscillations are the tone's and the
/// Gauss–Markov terms' (and the search costs a grid per decade).
const RES_LOWEST: f64 = 20.0;

/// Quality factors Q = πf_rτr of the resonance grid: from a band as wide as its
/// centre frequency to a peak an eighth of it; sharper ones are refined from
/// the best of these (up to [`RES_Q_MAX`]) or are the tone.
const RES_Q: [f64; 4] = [1.0, 2.0, 4.0, 8.0];

/// Bounds of the refined quality factor. Below Q = 1 the band is wider than its
/// centre frequency and its spectrum has no peak to speak of: a low-pass
/// shape, which the Gauss–Markov terms describe (a free Q below 1 takes the
/// sensor's filter and moves the long-tau coefficients). Above Q = 30 it is a
/// line, which the tone describes
/// with one parameter fewer. A resonance refined onto either bound is dropped.
const RES_Q_MIN: f64 = 1.0;
const RES_Q_MAX: f64 = 30.0;

/// Nelder–Mead tolerance (simplex size) in ln f_r and ln τr of a resonance: its curve is
/// smooth in both (the damping blurs the phase πf_rτ that makes the tone's
/// frequency sharp).
const RES_TOL: f64 = 1e-3;

/// Most loss evaluations of the refinement of a resonance.
const RES_EVALS: usize = 120;

/// Lowest quality factor of a resonance with a quadrature part: a
/// Butterworth second-order low-pass has Q = πf_rτr = ½ (poles at 135°), and a
/// sensor's filter that is one is what the quadrature part is for. A skewed
/// resonance refined onto this bound is dropped.
const SKEWED_Q_MIN: f64 = 0.4;

/// Quality factors of the grid of a resonance with a quadrature part: the
/// plain grid's and a Butterworth filter's.
const SKEWED_Q: [f64; 5] = [0.5, 1.0, 2.0, 4.0, 8.0];

/// Fewest periods of a tone in the longest tau: slower ones would explain the
/// scatter of the last few, least independent estimates (their bump at
/// τ ≈ 0.37/f₀ stays more than a decade inside the curve).
pub const SINE_PERIODS: f64 = 10.0;

/// The tones, the resonance and the bounded motion's correlation time of a
/// structure, the last two each if it has one.
pub type Extras = (Tones, Option<Resonance>, Option<f64>);

/// Columns of a structure beyond the IEEE terms and its Gauss–Markov times.
fn extra_columns((sine, resonance, motion): Extras) -> usize {
    sine.len() + resonance.map_or(0, Resonance::columns) + usize::from(motion.is_some())
}

/// The basis of a structure: IEEE columns, one column per GM time, then one per
/// tone, then the resonance's if any, then the bounded motion if any.
pub fn design(data: &Data, fs: f64, gm_tau: &[f64], extras: Extras) -> Mat<f64> {
    let (sine, resonance, motion) = extras;
    let g = gm_tau.len();
    let tone = IEEE_TERMS + g;
    let osc = tone + sine.len();
    let after = osc + resonance.map_or(0, Resonance::columns);
    let k = tone + extra_columns(extras);
    Mat::from_fn(data.len(), k, |i, j| {
        if j < IEEE_TERMS {
            data.ieee(i)[j]
        } else if j < tone {
            basis::gauss_markov(data.m[i], basis::gm_rate(gm_tau[j - IEEE_TERMS], fs))
        } else if j < osc {
            basis::sinusoid(data.m[i], sine.as_slice()[j - tone] / fs)
        } else if let (Some(r), true) = (resonance, j < after) {
            r.column(data.m[i], fs, j - osc)
        } else {
            let u = basis::gm_rate(motion.unwrap_or(1.0), fs);
            basis::motion(data.taus[i], data.m[i], u)
        }
    })
}

fn allowed_with(ieee: &[bool; IEEE_TERMS], extra: usize) -> Vec<bool> {
    let mut a = ieee.to_vec();
    a.extend(std::iter::repeat_n(true, extra));
    a
}

/// Fewest taus per decade for a tone: on a sparser grid a free frequency
/// places the curve's oscillation to fit any few points.
const SINE_MIN_DENSITY: f64 = 3.0;

/// Candidate tone frequencies (Hz): 10^(j/96) from [`SINE_PERIODS`] periods in
/// the longest tau up to fs/2, and fs/2 itself. Empty on grids sparser than
/// [`SINE_MIN_DENSITY`]. (A tone near fs/2 falls as 1/τ² like quantization
/// noise, but only at odd cluster sizes: the even ones tell the two apart.)
pub fn frequency_grid(data: &Data, fs: f64) -> Vec<f64> {
    log_grid(data, fs, FREQ_PER_DECADE)
}

/// Candidate resonance frequencies (Hz): [`RES_PER_DECADE`] per decade from
/// fs/[`RES_LOWEST`] (or the tone's lowest, if higher) to fs/2, and fs/2.
pub fn resonance_grid(data: &Data, fs: f64) -> Vec<f64> {
    let lowest = fs / RES_LOWEST;
    log_grid(data, fs, RES_PER_DECADE)
        .into_iter()
        .filter(|&f| f >= lowest * (1.0 - 1e-12))
        .collect()
}

/// 10^(j/`per_decade`) Hz from [`SINE_PERIODS`] periods in the longest tau up
/// to fs/2, and fs/2; empty on grids sparser than [`SINE_MIN_DENSITY`].
fn log_grid(data: &Data, fs: f64, per_decade: f64) -> Vec<f64> {
    let (first, last) = (data.taus[0], data.taus[data.len() - 1]);
    let decades = (last / first).log10();
    if data.len() < 2 || (data.len() - 1) as f64 / decades < SINE_MIN_DENSITY {
        return Vec::new();
    }
    let top = 0.5 * fs;
    let lo = (SINE_PERIODS / last).log10();
    let hi = top.log10();
    if lo >= hi {
        return Vec::new();
    }
    let (a, b) = (
        (lo * per_decade).ceil() as i64,
        (hi * per_decade).floor() as i64,
    );
    let mut grid: Vec<f64> = (a..=b).map(|j| 10f64.powf(j as f64 / per_decade)).collect();
    grid.push(top);
    grid
}

/// Golden-section search of f(e^x) over x in [ln lo, ln hi] down to an interval
/// of `tol` in x; returns the best point found, or `start` when nothing beats it.
fn golden(lo: f64, hi: f64, start: f64, tol: f64, f: impl Fn(f64) -> f64) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (lo.ln(), hi.ln());
    let at = |x: f64| f(x.exp());
    let best_start = at(start.ln());
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let mut fc = at(c);
    let mut fd = at(d);
    while b - a > tol {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = at(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = at(d);
        }
    }
    let (x, fx) = if fc < fd { (c, fc) } else { (d, fd) };
    if fx <= best_start {
        x.exp()
    } else {
        start
    }
}

/// Nelder–Mead minimisation of `f` over the plane from the simplex `start`,
/// until its vertices are within `tol` of each other or `evals` evaluations.
fn nelder_mead(
    start: [[f64; 2]; 3],
    tol: f64,
    evals: usize,
    f: impl Fn([f64; 2]) -> f64,
) -> [f64; 2] {
    let mut pts: Vec<([f64; 2], f64)> = start.iter().map(|&p| (p, f(p))).collect();
    let mut used = 3;
    let along =
        |a: [f64; 2], b: [f64; 2], t: f64| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
    while used < evals {
        pts.sort_by(|a, b| a.1.total_cmp(&b.1));
        let size = pts[1..]
            .iter()
            .map(|p| {
                (p.0[0] - pts[0].0[0])
                    .abs()
                    .max((p.0[1] - pts[0].0[1]).abs())
            })
            .fold(0.0, f64::max);
        if size < tol {
            break;
        }
        let centre = along(pts[0].0, pts[1].0, 0.5);
        let worst = pts[2];
        let reflected = along(centre, worst.0, -1.0);
        let fr = f(reflected);
        used += 1;
        if fr < pts[0].1 {
            let expanded = along(centre, worst.0, -2.0);
            let fe = f(expanded);
            used += 1;
            pts[2] = if fe < fr {
                (expanded, fe)
            } else {
                (reflected, fr)
            };
        } else if fr < pts[1].1 {
            pts[2] = (reflected, fr);
        } else {
            let contracted = along(centre, worst.0, 0.5);
            let fc = f(contracted);
            used += 1;
            if fc < worst.1 {
                pts[2] = (contracted, fc);
            } else {
                // Shrink towards the best vertex.
                for k in 1..3 {
                    let p = along(pts[0].0, pts[k].0, 0.5);
                    pts[k] = (p, f(p));
                }
                used += 2;
            }
        }
    }
    pts.into_iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(start[0], |p| p.0)
}

/// Shortest correlation time, in samples: φ = e⁻² ≈ 0.14 at half a sample;
/// a faster Gauss–Markov term is white noise to any cluster size, and would
/// take N's place for a percent of shape at the first taus.
const FASTEST: f64 = 0.5;

/// Candidate correlation times: 10^(j/6) s from [`FASTEST`] samples to three
/// times the longest tau.
pub fn time_grid(data: &Data, fs: f64) -> Vec<f64> {
    let lo = (FASTEST / fs).log10();
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
    /// The tones, held fixed while the times are searched (and beside which
    /// another tone is searched).
    sine: Tones,
    /// The resonance, held fixed while the times and the tone are searched.
    resonance: Option<Resonance>,
    /// The bounded motion's correlation time, held fixed while the times are
    /// polished around it.
    motion: Option<f64>,
}

impl Searcher<'_> {
    /// Loss of the best θ for these times at the searcher's fixed δ².
    fn loss(&self, times: &[f64]) -> f64 {
        self.loss_with(times, self.sine)
    }

    /// Loss of the best θ for these times and these tones.
    fn loss_with(&self, times: &[f64], sine: Tones) -> f64 {
        self.loss_full(times, sine, self.resonance)
    }

    /// Loss of the best θ for these times, these tones and this resonance.
    fn loss_full(&self, times: &[f64], sine: Tones, resonance: Option<Resonance>) -> f64 {
        let extras = (sine, resonance, self.motion);
        let basis = design(self.data, self.fs, times, extras);
        let extra = times.len() + extra_columns(extras);
        let allowed = allowed_with(&self.ieee, extra);
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
        let base = times.to_vec();
        times[which] = golden(lo, hi, base[which], TIME_TOL, |t| {
            let mut probe = base.clone();
            probe[which] = t;
            self.loss(&probe)
        });
    }

    /// Refine each time in turn within a factor `span`, twice, keeping the
    /// times at least [`MIN_RATIO`] apart.
    fn polish(&self, times: &mut [f64], span: f64) {
        for _round in 0..2 {
            for which in 0..times.len() {
                // The refinement stays within the grid's range too.
                let mut lo = (times[which] / span).max(FASTEST / self.fs);
                let mut hi = times[which] * span;
                // Two terms closer than a factor of 2 in τc are one term.
                if which > 0 {
                    lo = lo.max(times[which - 1] * MIN_RATIO);
                }
                if which + 1 < times.len() {
                    hi = hi.min(times[which + 1] / MIN_RATIO);
                }
                if lo < hi {
                    self.refine(times, which, lo, hi);
                }
            }
        }
    }

    /// Best frequency on the grid of one more tone beside the searcher's, with
    /// these times, and its loss (None when the curve is too short for any tone
    /// or the structure has [`MAX_TONES`]); [`Self::refine_frequency`] then
    /// refines it.
    fn coarse_frequency(&self, times: &[f64]) -> Option<(f64, f64)> {
        if self.sine.is_full() {
            return None;
        }
        frequency_grid(self.data, self.fs)
            .into_iter()
            .map(|f| (f, self.loss_with(times, self.sine.with(f))))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Each of `tones` refined in turn ([`Self::refine_frequency`]) with the
    /// others in place; the searcher's own tones are left as they were.
    fn refine_tones(&mut self, times: &[f64], mut tones: Tones) -> Tones {
        let fixed = self.sine;
        for k in 0..tones.len() {
            self.sine = tones.without(k);
            tones = tones.replaced(k, self.refine_frequency(times, tones.as_slice()[k]));
        }
        self.sine = fixed;
        tones
    }

    /// Each of `tones` searched again on the whole frequency grid with the
    /// others and the searcher's resonance and motion in place, then refined: a
    /// term that enters beside a line can take part of what the line had
    /// described and move its best frequency by more than the refinement's one
    /// grid step. The searcher's own tones are left as they were.
    fn rescan_tones(&mut self, times: &[f64], mut tones: Tones) -> Tones {
        let fixed = self.sine;
        for k in 0..tones.len() {
            self.sine = tones.without(k);
            let f = tones.as_slice()[k];
            let coarse = self.coarse_frequency(times).map_or(f, |(g, _)| g);
            tones = tones.replaced(k, self.refine_frequency(times, coarse));
        }
        self.sine = fixed;
        tones
    }

    /// A finer scan within one grid step of `f`, then golden section. The
    /// tone's curve at τ has phase πf₀τ, so at the longest tau the loss
    /// oscillates in ln f₀ with a period of about 1/(f₀τ_max): the fine scan
    /// steps a tenth of that (at most [`FINE_SCAN`] steps; beyond, the tone has
    /// faded under the other terms long before τ_max).
    fn refine_frequency(&self, times: &[f64], f: f64) -> f64 {
        let loss = |f: f64| self.loss_with(times, self.sine.with(f));
        let top = 0.5 * self.fs;
        let span = std::f64::consts::LN_10 / FREQ_PER_DECADE;
        let tau_max = self.data.taus[self.data.len() - 1];
        let step = (0.1 / (std::f64::consts::PI * f * tau_max)).max(2.0 * span / FINE_SCAN);
        let n = (span / step).ceil() as i64;
        let fine = (-n..=n)
            .map(|j| f * (j as f64 * step).exp())
            .filter(|&g| g <= top)
            .map(|g| (loss(g), g))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map_or(f, |(_, g)| g);
        let hi = (fine * step.exp()).min(top);
        golden(fine * (-step).exp(), hi, fine, FREQ_TOL, loss)
    }

    /// Best resonance (with a quadrature part when `skewed`) on the grid of
    /// frequencies × [`RES_Q`] (× [`SKEWED_Q`]) with these times, and its loss
    /// (None when the curve is too short for one).
    fn coarse_resonance(&self, times: &[f64], skewed: bool) -> Option<(Resonance, f64)> {
        let qualities: &[f64] = if skewed { &SKEWED_Q } else { &RES_Q };
        resonance_grid(self.data, self.fs)
            .into_iter()
            .flat_map(|freq| {
                qualities.iter().map(move |q| Resonance {
                    freq,
                    tau: q / (std::f64::consts::PI * freq),
                    skewed,
                })
            })
            .map(|r| (r, self.loss_full(times, self.sine, Some(r))))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Refinement of (ln f_r, ln τr) by Nelder–Mead from the grid point (the
    /// two are correlated with each other and with the Q and N terms, which
    /// coordinate searches follow slowly), f_r kept ≤ fs/2 and
    /// Q = πf_rτr in [[`RES_Q_MIN`] (or [`SKEWED_Q_MIN`]), [`RES_Q_MAX`]].
    fn refine_resonance(&self, times: &[f64], start: Resonance) -> Resonance {
        let pi = std::f64::consts::PI;
        let top = (0.5 * self.fs).ln();
        let q_min = if start.skewed {
            SKEWED_Q_MIN
        } else {
            RES_Q_MIN
        };
        let clamp = |p: [f64; 2]| -> [f64; 2] {
            let lf = p[0].min(top);
            let q_lo = (q_min / pi).ln() - lf;
            let q_hi = (RES_Q_MAX / pi).ln() - lf;
            [lf, p[1].clamp(q_lo, q_hi)]
        };
        let at = |p: [f64; 2]| Resonance {
            freq: p[0].exp(),
            tau: p[1].exp(),
            ..start
        };
        let loss = |p: [f64; 2]| self.loss_full(times, self.sine, Some(at(clamp(p))));
        let step = std::f64::consts::LN_10 / RES_PER_DECADE;
        let start = [start.freq.ln(), start.tau.ln()];
        let starts = [
            start,
            [start[0] - step, start[1]],
            [start[0], start[1] + 0.3],
        ];
        let best = nelder_mead(starts, RES_TOL, RES_EVALS, loss);
        at(clamp(best))
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
        self.polish(&mut times, span);
        times
    }
}

/// A fitted structure: its times, which IEEE terms were allowed, the solution
/// and its information criterion.
#[derive(Debug, Clone)]
pub struct Candidate {
    pub gm_tau: Vec<f64>,
    /// Frequencies (Hz) of the structure's tones.
    pub sine: Tones,
    /// The resonance, if the structure has one.
    pub resonance: Option<Resonance>,
    /// The bounded motion's correlation time (s), if the structure has one.
    pub motion: Option<f64>,
    pub ieee: [bool; IEEE_TERMS],
    pub solution: Solution,
    pub bic: f64,
}

/// Number of free parameters of a solution: non-zero coefficients (a skewed
/// resonance's two are its variance and quadrature), a time (or frequency) for
/// every Gauss–Markov term, tone or bounded motion in use, and two (frequency
/// and damping) for a resonance in use, whose columns come before the bounded
/// motion's, last of `theta`.
pub fn parameters(theta: &[f64], resonance: Option<Resonance>, motion: bool) -> usize {
    let used = theta.iter().filter(|t| **t > 0.0).count();
    let res_columns = resonance.map_or(0, Resonance::columns);
    let res_start = theta.len() - res_columns - usize::from(motion);
    let in_use = |range: std::ops::Range<usize>| theta[range].iter().filter(|t| **t > 0.0).count();
    let times = in_use(IEEE_TERMS..res_start) + in_use(res_start + res_columns..theta.len());
    let oscillator = in_use(res_start..res_start + res_columns).min(1);
    used + times + 2 * oscillator
}

/// BIC by which each component beyond the IEEE terms (a Gauss–Markov term, a
/// tone, a resonance) must lower the criterion, on top of its parameters' own
/// penalty: 6 is "strong" evidence on Kass and Raftery's scale (JASA 90, 1995).
/// BIC counts each octave of overlapping Allan estimates as independent, which
/// they are not, so its own penalty lets a correlated wiggle of the long taus in
/// (the gains measured on clean and real channels: docs/noise.md).
pub const COMPONENT_EVIDENCE: f64 = 6.0;

impl Candidate {
    /// Components beyond the IEEE terms in use: Gauss–Markov terms with a
    /// positive variance, the tones, the resonance — twice when it is skewed: its
    /// quadrature part is asked the evidence of a component of its own (counted
    /// once, a skewed band takes a line beside it as well).
    pub fn components(&self) -> usize {
        let theta = &self.solution.theta;
        let gm = (0..self.gm_tau.len())
            .filter(|k| theta[IEEE_TERMS + k] > 0.0)
            .count();
        gm + extra_columns((self.sine, self.resonance, self.motion))
    }

    /// The correlation times of the Gauss–Markov terms with a positive variance.
    pub fn gm_in_use(&self) -> Vec<f64> {
        (self.gm_tau.iter().enumerate())
            .filter(|&(k, _)| self.solution.theta[IEEE_TERMS + k] > 0.0)
            .map(|(_, &t)| t)
            .collect()
    }

    /// What structure selection minimises: the BIC, with [`COMPONENT_EVIDENCE`]
    /// asked of every component beyond the IEEE terms.
    pub fn score(&self) -> f64 {
        self.bic + COMPONENT_EVIDENCE * self.components() as f64
    }

    /// The typed terms of the candidate: every term whose fitted variance is > 0,
    /// in the order of [`super::Kind::ALL`].
    pub fn terms(&self, fs: f64) -> Vec<Term> {
        let c = self;
        let theta = &c.solution.theta;
        let mut terms: Vec<Term> = (0..IEEE_TERMS)
            .filter(|&j| theta[j] > 0.0)
            .map(|j| Term::ieee(j, theta[j]))
            .collect();
        terms.extend(
            (c.gm_tau.iter().enumerate())
                .filter(|(k, _)| theta[IEEE_TERMS + k] > 0.0)
                .map(|(k, &tau_c)| Term::GaussMarkov {
                    variance: theta[IEEE_TERMS + k],
                    tau_c,
                }),
        );
        let tone_column = IEEE_TERMS + c.gm_tau.len();
        let mut tones: Vec<Term> = (c.sine.as_slice().iter().enumerate())
            .filter(|(k, _)| theta[tone_column + k] > 0.0)
            .map(|(k, &freq)| Term::Tone {
                variance: theta[tone_column + k],
                freq,
            })
            .collect();
        tones.sort_by(|a, b| match (a, b) {
            (Term::Tone { freq: x, .. }, Term::Tone { freq: y, .. }) => x.total_cmp(y),
            _ => std::cmp::Ordering::Equal,
        });
        terms.extend(tones);
        let res_column = tone_column + c.sine.len();
        let res_columns = c.resonance.map_or(0, Resonance::columns);
        if let Some(r) = c.resonance {
            let (variance, skew) = r.variance_and_skew(&theta[res_column..], fs);
            if variance > 0.0 {
                terms.push(Term::Resonance {
                    variance,
                    freq: r.freq,
                    tau: r.tau,
                    skew,
                });
            }
        }
        if let Some(tau_c) = c.motion {
            let variance = theta[res_column + res_columns];
            if variance > 0.0 {
                terms.push(Term::Motion { variance, tau_c });
            }
        }
        terms
    }
}

/// Fit a structure with given correlation times, tone and resonance (no search).
pub fn candidate(
    data: &Data,
    fs: f64,
    ieee: [bool; IEEE_TERMS],
    gm_tau: Vec<f64>,
    extras: Extras,
    d2: f64,
) -> CoreResult<Candidate> {
    let (sine, resonance, motion) = extras;
    let basis = design(data, fs, &gm_tau, extras);
    let extra = gm_tau.len() + extra_columns(extras);
    let allowed = allowed_with(&ieee, extra);
    let solution = estimate::solve_joint(
        estimate::Problem {
            data,
            basis: &basis,
            allowed: &allowed,
        },
        d2,
        None,
    )?;
    let p = parameters(&solution.theta, resonance, motion.is_some());
    let bic = solution.loss + p as f64 * data.n_eff().max(2.0).ln();
    Ok(Candidate {
        gm_tau,
        sine,
        resonance,
        motion,
        ieee,
        solution,
        bic,
    })
}

/// The structure of `terms` with their times and frequencies held and every
/// variance fitted again (a tone's frequency measured in the spectrum, where a
/// line is far sharper than on the Allan curve, placed in the Allan fit).
pub fn held(data: &Data, fs: f64, terms: &[Term]) -> CoreResult<Candidate> {
    let mut ieee = [false; IEEE_TERMS];
    let (mut gm_tau, mut freqs) = (Vec::new(), Vec::new());
    let (mut resonance, mut motion) = (None, None);
    for term in terms {
        match *term {
            Term::GaussMarkov { tau_c, .. } => gm_tau.push(tau_c),
            Term::Tone { freq, .. } => freqs.push(freq),
            Term::Resonance {
                freq, tau, skew, ..
            } => {
                resonance = Some(Resonance {
                    freq,
                    tau,
                    skewed: skew != 0.0,
                })
            }
            Term::Motion { tau_c, .. } => motion = Some(tau_c),
            _ => {
                if let Some(j) = Kind::IEEE.iter().position(|&k| k == term.kind()) {
                    ieee[j] = true;
                }
            }
        }
    }
    if freqs.len() > MAX_TONES {
        return Err(CoreError::InvalidArgument(format!(
            "terms hold {} tones; a model has at most {MAX_TONES}",
            freqs.len()
        )));
    }
    let extras = (Tones::from_slice(&freqs), resonance, motion);
    candidate(data, fs, ieee, gm_tau, extras, 0.0)
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
    let searcher = Searcher {
        data,
        fs,
        ieee,
        d2,
        sine: Tones::NONE,
        resonance: None,
        motion: None,
    };
    let times = searcher.times(gm, seed);
    let first = candidate(data, fs, ieee, times, (Tones::NONE, None, None), d2)?;
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
    let second = candidate(
        data,
        fs,
        ieee,
        times,
        (Tones::NONE, None, None),
        first.solution.d2,
    )?;
    Ok(if second.solution.loss < first.solution.loss {
        second
    } else {
        first
    })
}

/// Add a tone to the Gauss–Markov times `gm_tau`, the tones `tones` and a fixed
/// `resonance`: its frequency searched, then the times refined around theirs
/// with the tone in place, every tone's frequency once more; refined again at
/// the discrepancy the toned fit settles on when that moved by more than a
/// factor of two. None when the curve is too short for a tone, the structure
/// has [`MAX_TONES`] or, when `gated` (model selection), the grid finds no use
/// for one or a tone is refined onto the grid's slowest frequencies.
pub fn with_sine(
    data: &Data,
    fs: f64,
    ieee: [bool; IEEE_TERMS],
    (gm_tau, tones, resonance): (&[f64], Tones, Option<Resonance>),
    d2: f64,
    gated: bool,
) -> CoreResult<Option<Candidate>> {
    let step = 10f64.powf(1.0 / PER_DECADE);
    // Times and frequencies polished at δ² from the tones found.
    let polish = |d2: f64, mut times: Vec<f64>, found: Tones| -> CoreResult<Candidate> {
        let mut searcher = Searcher {
            data,
            fs,
            ieee,
            d2,
            sine: found,
            resonance,
            motion: None,
        };
        searcher.polish(&mut times, step);
        searcher.sine = Tones::NONE;
        let found = searcher.refine_tones(&times, found);
        candidate(data, fs, ieee, times, (found, resonance, None), d2)
    };
    let searcher = Searcher {
        data,
        fs,
        ieee,
        d2,
        sine: tones,
        resonance,
        motion: None,
    };
    let Some((f, toned)) = searcher.coarse_frequency(gm_tau) else {
        return Ok(None);
    };
    // A tone the grid finds no use for is not refined: where the grid's best
    // tone (within a quarter radian of any real one up to 6/f₀) gains less
    // than a quarter of the 2 ln n_eff that BIC asks of it, the refinement,
    // which moves the frequency by at most a grid step, does not make it up.
    if gated && toned > searcher.loss(gm_tau) - 0.5 * data.n_eff().max(2.0).ln() {
        return Ok(None);
    }
    // A tone refined onto the grid's slowest frequencies is the longest taus'
    // rise or scatter, which the loss would bend a slower one to (a wander, not
    // a line: it takes the rise from K). Like a resonance on a bound of its Q,
    // it is dropped.
    let lowest = frequency_grid(data, fs).first().copied().unwrap_or(0.0);
    let on_bound = |c: &Candidate| {
        let slowest = c
            .sine
            .as_slice()
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        gated && slowest <= lowest * SINE_BOUND
    };
    let first = polish(d2, gm_tau.to_vec(), tones.with(f))?;
    let settled = first.solution.d2;
    if settled <= 2.0 * d2 && settled >= 0.5 * d2 {
        return Ok((!on_bound(&first)).then_some(first));
    }
    // The grid again at the discrepancy the toned fit settled on: at the one
    // before, inflated by what the tone now describes, the loss weighs every tau
    // alike and a line whose nulls lie under a larger one's curve found the wrong
    // basin (0.42 Hz for a 0.37 Hz line beside a 0.05 Hz one, 83 % of taus
    // covered), which the refinement within a grid step keeps.
    let settled_searcher = Searcher {
        d2: settled,
        ..searcher
    };
    let again = (settled_searcher.coarse_frequency(&first.gm_tau)).map_or(f, |(g, _)| g);
    let second = polish(settled, first.gm_tau.clone(), tones.with(again))?;
    let better = if second.solution.loss < first.solution.loss {
        second
    } else {
        first
    };
    Ok((!on_bound(&better)).then_some(better))
}

/// Add a resonance (with a quadrature part when `skewed`) to the Gauss–Markov
/// times `gm_tau` and tones `sine`: grid, refinement, the times and the tones'
/// frequencies polished with it in place; refined again at the discrepancy the
/// fit settles on when that moved by more than a factor of two. None when the
/// curve is too short for one or, when `gated`, the grid's best gains less than
/// a quarter of the BIC penalty of its three parameters (the tone's gate) or it
/// is refined onto a bound of its Q.
pub fn with_resonance(
    data: &Data,
    fs: f64,
    ieee: [bool; IEEE_TERMS],
    (gm_tau, sine, skewed): (&[f64], Tones, bool),
    d2: f64,
    gated: bool,
) -> CoreResult<Option<Candidate>> {
    let step = 10f64.powf(1.0 / PER_DECADE);
    let searcher = Searcher {
        data,
        fs,
        ieee,
        d2,
        sine,
        resonance: None,
        motion: None,
    };
    let Some((res, loss)) = searcher.coarse_resonance(gm_tau, skewed) else {
        return Ok(None);
    };
    if gated && loss > searcher.loss(gm_tau) - 0.75 * data.n_eff().max(2.0).ln() {
        return Ok(None);
    }
    let polish = |d2: f64, mut times: Vec<f64>, sine: Tones, res: Resonance| {
        let mut s = Searcher {
            data,
            fs,
            ieee,
            d2,
            sine,
            resonance: None,
            motion: None,
        };
        let res = s.refine_resonance(&times, res);
        s.resonance = Some(res);
        s.polish(&mut times, step);
        s.sine = Tones::NONE;
        // A band beside a line can take part of it and move it off its
        // frequency: the line is searched again.
        let sine = s.rescan_tones(&times, sine);
        candidate(data, fs, ieee, times, (sine, Some(res), None), d2)
    };
    let q_min = if skewed { SKEWED_Q_MIN } else { RES_Q_MIN };
    let on_bound = |c: &Candidate| {
        c.resonance.is_some_and(|r| {
            let q = r.quality();
            q >= 0.99 * RES_Q_MAX || q <= 1.01 * q_min
        })
    };
    let first = polish(d2, gm_tau.to_vec(), sine, res)?;
    let settled = first.solution.d2;
    if settled <= 2.0 * d2 && settled >= 0.5 * d2 {
        return Ok((!(gated && on_bound(&first))).then_some(first));
    }
    let second = polish(
        settled,
        first.gm_tau.clone(),
        first.sine,
        first.resonance.unwrap_or(res),
    )?;
    let better = if second.solution.loss < first.solution.loss {
        second
    } else {
        first
    };
    Ok((!(gated && on_bound(&better))).then_some(better))
}

/// The structure `opts` names, fitted as it is (no selection): the IEEE terms and
/// Gauss–Markov terms, then the tone, the resonance and the bounded motion each
/// searched on top of what came before. Any of them may be the only term.
pub fn requested(data: &Data, fs: f64, opts: &Options) -> CoreResult<Candidate> {
    let ieee = opts.ieee();
    let gm = opts.count(Kind::GaussMarkov);
    let base = fit_structure(data, fs, ieee, 0, 0.0, &[]);
    let d2 = base.as_ref().map_or(0.0, |b| b.solution.d2);
    let mut current = if gm == 0 {
        base.ok()
    } else {
        Some(fit_structure(data, fs, ieee, gm, d2, &[])?)
    };
    let shape = |c: &Option<Candidate>| match c {
        Some(c) => (c.gm_tau.clone(), c.sine, c.resonance, c.solution.d2),
        None => (Vec::new(), Tones::NONE, None, d2),
    };
    for _ in 0..opts.count(Kind::Tone) {
        let (times, tones, _, d2) = shape(&current);
        let toned = with_sine(data, fs, ieee, (&times, tones, None), d2, false)?;
        current = toned.or(current);
    }
    if opts.count(Kind::Resonance) > 0 {
        // The resonance with and without a quadrature part; the lower BIC is its fit.
        let (times, sine, _, d2) = shape(&current);
        let mut fitted: Option<Candidate> = None;
        for skewed in [false, true] {
            let shape = (times.as_slice(), sine, skewed);
            if let Some(c) = with_resonance(data, fs, ieee, shape, d2, false)? {
                if fitted.as_ref().is_none_or(|f| c.bic < f.bic) {
                    fitted = Some(c);
                }
            }
        }
        current = fitted.or(current);
    }
    if opts.count(Kind::Motion) > 0 {
        let (times, sine, res, d2) = shape(&current);
        let moved = with_motion(data, fs, ieee, (&times, sine, res), d2, false)?;
        current = moved.or(current);
    }
    current.ok_or_else(|| {
        CoreError::Numerical(
            "noise-model fit found no model with a positive Allan variance at every tau".into(),
        )
    })
}

/// Stepwise selection of the IEEE terms among `allowed`: remove the term whose
/// removal lowers the score most, while one does; then add back the removed term
/// that lowers it most, if one does, and remove again. Removal alone is greedy:
/// with K and R in place B can look redundant and go first, and once K and R go
/// too nothing brings it back.
fn eliminate(
    data: &Data,
    fs: f64,
    allowed: [bool; IEEE_TERMS],
    mut best: Candidate,
) -> CoreResult<Candidate> {
    loop {
        let active = |j: usize, c: &Candidate| c.ieee[j] && c.solution.theta[j] > 0.0;
        let mut improved: Option<Candidate> = None;
        for j in (0..IEEE_TERMS).filter(|&j| active(j, &best)) {
            let mut ieee = best.ieee;
            ieee[j] = false;
            // A structure that fits no positive curve is no step to take.
            let Ok(trial) = rebuilt(data, fs, ieee, &best) else {
                continue;
            };
            let bar = improved.as_ref().map_or(best.score(), |c| c.score());
            if trial.score() < bar {
                improved = Some(trial);
            }
        }
        if improved.is_none() {
            for j in (0..IEEE_TERMS).filter(|&j| allowed[j] && !active(j, &best)) {
                let mut ieee = best.ieee;
                ieee[j] = true;
                let Ok(trial) = rebuilt(data, fs, ieee, &best) else {
                    continue;
                };
                let bar = improved.as_ref().map_or(best.score(), |c| c.score());
                // Strictly lower by a margin, so that add and remove cannot cycle
                // on a tie.
                if trial.score() < bar - 1e-9 && active(j, &trial) {
                    improved = Some(trial);
                }
            }
        }
        match improved {
            Some(c) => best = c,
            None => return Ok(best),
        }
    }
}

/// `base`'s structure with the IEEE terms `ieee`, refitted.
pub(super) fn rebuilt(
    data: &Data,
    fs: f64,
    ieee: [bool; IEEE_TERMS],
    base: &Candidate,
) -> CoreResult<Candidate> {
    candidate(
        data,
        fs,
        ieee,
        base.gm_tau.clone(),
        (base.sine, base.resonance, base.motion),
        base.solution.d2,
    )
}

/// Automatic selection over 0..=`max_gm` Gauss–Markov terms and the IEEE terms
/// in `ieee`, each also with up to `max_tones` tones, then with a resonance when
/// `resonance`, then with a bounded motion when `motion`.
pub fn select(
    data: &Data,
    fs: f64,
    ieee: [bool; IEEE_TERMS],
    max_gm: usize,
    (max_tones, resonance, motion): (usize, bool, bool),
) -> CoreResult<Candidate> {
    let base = fit_structure(data, fs, ieee, 0, 0.0, &[])?;
    let mut best = eliminate(data, fs, ieee, base.clone())?;
    let ieee_only = best.clone();
    // The structure BIC alone prefers, without the evidence asked of components.
    let mut by_bic = best.clone();
    let mut seed: Vec<f64> = Vec::new();
    for gm in 1..=max_gm {
        let full = fit_structure(data, fs, ieee, gm, base.solution.d2, &seed)?;
        seed = full.gm_tau.clone();
        let reduced = eliminate(data, fs, ieee, full)?;
        if reduced.bic < by_bic.bic {
            by_bic = reduced.clone();
        }
        if reduced.score() < best.score() {
            best = reduced;
        }
    }
    // A slow Gauss–Markov term in place of the walk. The times above are searched
    // with K and R in the model, which take the rise past the floor first; a
    // bounded wander that falls again at the longest taus then never gets a term
    // of its own, and which structure wins moves with the tau grid.
    if best.solution.theta[WALK] > 0.0 && best.gm_tau.len() < max_gm {
        let mut still = ieee;
        still[WALK] = false;
        still[RAMP] = false;
        let gm = best.gm_tau.len() + 1;
        if let Ok(wander) = fit_structure(data, fs, still, gm, base.solution.d2, &best.gm_tau) {
            let reduced = eliminate(data, fs, ieee, wander)?;
            if reduced.bic < by_bic.bic {
                by_bic = reduced.clone();
            }
            if reduced.score() < best.score() {
                best = reduced;
            }
        }
    }
    let plain = best.clone();
    // The lowest-scoring structure with tones, kept or not: the base a resonance
    // may complete.
    let mut toned: Option<Candidate> = None;
    if max_tones > 0 {
        // The tone on its own, beside the best structure and beside the one BIC
        // alone prefers (refined around their times): a tone may complete a
        // structure that lost without it (a sensor's fast filter term and a line
        // can each lose alone and win together).
        let mut times = vec![Vec::new()];
        for t in [best.gm_tau.clone(), by_bic.gm_tau.clone()] {
            if !times.contains(&t) {
                times.push(t);
            }
        }
        for gm_tau in times {
            let start = (gm_tau, Tones::NONE, None);
            let budget = (base.solution.d2, max_tones);
            if let Some(c) = add_tones(data, fs, ieee, start, budget, &mut best)? {
                if toned.as_ref().is_none_or(|t| c.score() < t.score()) {
                    toned = Some(c);
                }
            }
        }
    }
    if resonance && misses_short_taus(data, &best) {
        let bases = Bases {
            plain: &plain,
            toned: toned.as_ref(),
        };
        best = add_resonance(data, fs, ieee, best, bases, max_tones)?;
    }
    if motion {
        // On the best structure, and on the IEEE terms alone: a fast
        // Gauss–Markov term takes the motion's white part when the motion is
        // not there to take it (a ring-laser gyro on a parked vehicle).
        let bases = if best.components() > 0 {
            vec![best.clone(), ieee_only]
        } else {
            vec![best.clone()]
        };
        for base in bases {
            // Only the times in use: an unused slot the polish revives is one more
            // component to pay for (a 15 s one beside the motion cost 6).
            let times = base.gm_in_use();
            let shape = (times.as_slice(), base.sine, base.resonance);
            if let Some(moved) = with_motion(data, fs, ieee, shape, base.solution.d2, true)? {
                keep_lower(data, fs, ieee, moved, &mut best)?;
            }
        }
    }
    Ok(best)
}

/// Largest cluster size, in multiples of [`RES_LOWEST`], of the taus a
/// resonance must be needed at.
const RES_REACH: f64 = 2.0;

/// Log miss of the model's Allan variance that counts as a miss: 0.05 (5 % in
/// variance, 2.5 % in deviation, half the coverage measure's tolerance: a miss
/// the coverage would not count is no reason to search).
const RES_MISS: f64 = 0.05;

/// Whether the structure misses the curve at the short taus a resonance shapes
/// (cluster sizes up to [`RES_REACH`]·[`RES_LOWEST`]): some log residual beyond
/// both [`RES_MISS`] and two of its standard errors. Only then is a resonance
/// searched: where the other terms follow the short taus, a resonance would
/// only re-describe the sensor's filter shape (gated on δ > 0 alone, it did on
/// an ADIS16405 gyro X, with a tone next to it, at no gain in coverage), and
/// its search costs as much as the tone's.
fn misses_short_taus(data: &Data, c: &Candidate) -> bool {
    (0..data.len())
        .filter(|&i| data.m[i] <= RES_REACH * RES_LOWEST)
        .any(|i| {
            let r = (data.y[i] - c.solution.model[i].ln()).abs();
            r > RES_MISS && r > 2.0 * data.v[i].sqrt()
        })
}

/// The best of `best`, `best` with a resonance, and, when `best` has a tone in
/// the resonance's range (≥ fs/[`RES_LOWEST`]), `plain` (the best structure
/// without one) with a resonance and then tones searched again on top (up to
/// `max_tones`): the tone may have taken the band the resonance describes better,
/// leaving the line next to it. A slower tone cannot have, and is kept. Also
/// the lowest-scoring toned structure of the tone search with a resonance.
fn add_resonance(
    data: &Data,
    fs: f64,
    ieee: [bool; IEEE_TERMS],
    mut best: Candidate,
    Bases { plain, toned }: Bases,
    max_tones: usize,
) -> CoreResult<Candidate> {
    let d2 = best.solution.d2;
    let mut bases = vec![best.clone()];
    if best.sine.as_slice().iter().any(|&f| f >= fs / RES_LOWEST) {
        bases.push(plain.clone());
    }
    if let Some(t) = toned.filter(|t| t.sine != best.sine || t.gm_tau != best.gm_tau) {
        bases.push(t.clone());
    }
    for base in &bases {
        for skewed in [false, true] {
            let shape = (base.gm_tau.as_slice(), base.sine, skewed);
            let Some(res) = with_resonance(data, fs, ieee, shape, d2, true)? else {
                continue;
            };
            keep_lower(data, fs, ieee, res.clone(), &mut best)?;
            if base.sine.is_empty() {
                // Tones on top, the resonance searched again after each (see `add_tones`).
                let on_top = (res.gm_tau.clone(), Tones::NONE, res.resonance);
                let budget = (res.solution.d2, max_tones);
                add_tones(data, fs, ieee, on_top, budget, &mut best)?;
            }
        }
    }
    Ok(best)
}

/// `c` reduced by [`eliminate`], put in `best` when it scores lower; returned.
fn keep_lower(
    data: &Data,
    fs: f64,
    ieee: [bool; IEEE_TERMS],
    c: Candidate,
    best: &mut Candidate,
) -> CoreResult<Candidate> {
    let reduced = eliminate(data, fs, ieee, c)?;
    if reduced.score() < best.score() {
        *best = reduced.clone();
    }
    Ok(reduced)
}

/// Structures besides the best one that a resonance may complete.
struct Bases<'a> {
    /// The best structure without tones.
    plain: &'a Candidate,
    /// The lowest-scoring structure with tones, whether or not it won: a line
    /// and the band beside it each leave the other's misfit.
    toned: Option<&'a Candidate>,
}

/// Tones searched one at a time on top of the times, tones and resonance of
/// `start`, up to `max_tones` (and [`MAX_TONES`]), from discrepancy `d2`; each
/// toned structure, reduced, replaces `best` when it scores lower. The next
/// tone is searched on top of the last whether or not that one won: two lines
/// each leave the other's misfit, so the first of them alone can lose and the
/// pair win. Where `start` has a resonance, it is searched again after each
/// tone with the tones in place: held fixed, a broad resonance that took a
/// line's power leaves the line little to gain. Returns the toned structure
/// that scored lowest, won or not.
fn add_tones(
    data: &Data,
    fs: f64,
    ieee: [bool; IEEE_TERMS],
    (gm_tau, tones, resonance): (Vec<f64>, Tones, Option<Resonance>),
    (d2, max_tones): (f64, usize),
    best: &mut Candidate,
) -> CoreResult<Option<Candidate>> {
    let mut current = (gm_tau, tones, d2);
    let mut lowest: Option<Candidate> = None;
    while current.1.len() < max_tones {
        let start = (current.0.as_slice(), current.1, resonance);
        let Some(toned) = with_sine(data, fs, ieee, start, current.2, true)? else {
            break;
        };
        // The next tone is searched at the discrepancy this structure settled on.
        current = (toned.gm_tau.clone(), toned.sine, toned.solution.d2);
        let moved = match resonance {
            Some(r) => {
                let shape = (current.0.as_slice(), current.1, r.skewed);
                with_resonance(data, fs, ieee, shape, current.2, true)?
            }
            None => None,
        };
        let reduced = keep_lower(data, fs, ieee, toned, best)?;
        if lowest.as_ref().is_none_or(|c| reduced.score() < c.score()) {
            lowest = Some(reduced);
        }
        if let Some(moved) = moved {
            keep_lower(data, fs, ieee, moved, best)?;
        }
    }
    Ok(lowest)
}

/// Shortest correlation time of a bounded motion, in samples: a faster one is
/// the quantization form 3/τ² at every cluster size, Q's.
const MOTION_FASTEST: f64 = 2.0;

/// Shortest correlation time of a bounded motion, in seconds. What the term is
/// for — a parked vehicle, a building, a bench settling — moves over seconds to
/// minutes; faster, a mount's motion is a vibration, the tone's and the
/// resonance's, and a motion there takes N's place at the shortest taus, where
/// the EDF is largest.
const MOTION_SHORTEST: f64 = 1.0;

/// Add a bounded motion (`basis::motion`) to the Gauss–Markov times `gm_tau`,
/// tone `sine` and `resonance`: correlation time by the grid of [`time_grid`]
/// from [`MOTION_FASTEST`] samples and [`MOTION_SHORTEST`] to the longest tau
/// (slower, it is white noise at every tau, N's), refined by golden section,
/// the Gauss–Markov times polished and the tone searched again with it in
/// place. None when no time fits or, when `gated`, the grid's best gains less
/// than the BIC penalty of its two parameters (the refinement cannot then make
/// up the evidence it must show; a quarter of it, the tone's gate, let the
/// search run on most clean axes and tripled the fit's time) or its time is
/// refined onto the lower bound.
pub fn with_motion(
    data: &Data,
    fs: f64,
    ieee: [bool; IEEE_TERMS],
    (gm_tau, sine, resonance): (&[f64], Tones, Option<Resonance>),
    d2: f64,
    gated: bool,
) -> CoreResult<Option<Candidate>> {
    let tau_max = data.taus[data.len() - 1];
    let searcher = |motion: Option<f64>| Searcher {
        data,
        fs,
        ieee,
        d2,
        sine,
        resonance,
        motion,
    };
    let loss = |t: f64| searcher(Some(t)).loss(gm_tau);
    let shortest = (MOTION_FASTEST / fs).max(MOTION_SHORTEST);
    let Some((coarse, best)) = time_grid(data, fs)
        .into_iter()
        .filter(|&t| t >= shortest && t <= tau_max)
        .map(|t| (t, loss(t)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
    else {
        return Ok(None);
    };
    if gated && best > searcher(None).loss(gm_tau) - 2.0 * data.n_eff().max(2.0).ln() {
        return Ok(None);
    }
    let step = 10f64.powf(1.0 / PER_DECADE);
    let lo = (coarse / step).max(shortest);
    let tau_c = golden(lo, (coarse * step).min(tau_max), coarse, TIME_TOL, loss);
    // On the lower bound it is a shape at the shortest taus the search cut off,
    // not a motion.
    if gated && tau_c <= shortest * (1.0 + TIME_TOL) {
        return Ok(None);
    }
    let mut times = gm_tau.to_vec();
    let mut moving = searcher(Some(tau_c));
    moving.polish(&mut times, step);
    // The tone searched again with the motion in place: the line found without
    // it had also been bent to the motion's white part (on a simulated gyro with
    // lines at 1.2 and 2.1 Hz on a rocking vehicle, 1.217 Hz refined to 1.25 Hz,
    // and the structure with both scored 12 lower).
    moving.sine = Tones::NONE;
    let tones = moving.rescan_tones(&times, sine);
    if !tones.is_empty() {
        moving.sine = tones;
        moving.polish(&mut times, step);
    }
    let extras = (tones, resonance, Some(tau_c));
    candidate(data, fs, ieee, times, extras, d2).map(Some)
}

/// Slot of the rate random walk K among the IEEE terms.
pub(super) const WALK: usize = 3;

/// Slot of the rate ramp R among the IEEE terms.
pub(super) const RAMP: usize = 4;

/// BIC by which a structure with a rate ramp must beat the best one without: 2,
/// "positive" evidence on Kass and Raftery's scale (JASA 90, 1995). A ramp is a trend, what the warm-up and temperature
/// analyses are for; the random walk is the still sensor's own term, so where
/// the last, nearly dependent taus fit both alike the structure keeps the walk
/// (and `ambiguity` reports neither value as resolved).
const RAMP_EVIDENCE: f64 = 2.0;

/// When `best` has a rate ramp, select again without one (`kinds`: whether a
/// tone and a resonance may enter, as for [`select`]) and keep that unless the
/// ramp lowers the score by at least [`RAMP_EVIDENCE`] (asked of the ramp at
/// this last step only: asked at every step of the selection, it moved the
/// structures chosen on real channels and predicted their second halves worse).
pub fn prefer_random_walk(
    data: &Data,
    fs: f64,
    ieee: [bool; IEEE_TERMS],
    max_gm: usize,
    kinds: (usize, bool, bool),
    best: Candidate,
) -> CoreResult<Candidate> {
    if best.solution.theta[RAMP] <= 0.0 {
        return Ok(best);
    }
    let mut without = ieee;
    without[RAMP] = false;
    // Without the ramp no structure may describe the curve at all: keep it then.
    let Ok(alternative) = select(data, fs, without, max_gm, kinds) else {
        return Ok(best);
    };
    Ok(if alternative.score() < best.score() + RAMP_EVIDENCE {
        alternative
    } else {
        best
    })
}
