//! The datasheet values N, B, K a fitted model implies, with their uncertainty
//! propagated from the fit's covariance: the numbers a user reads.
//!
//! A datasheet quotes what the curve shows, not which terms made it:
//! - N: √ of the white level a reader draws through τ = 1 s, Σ [`Term::white_share`];
//! - K: √ of the walk that keeps rising to the end of the record, Σ [`Term::walk_share`];
//! - B: the floor of the model's deviation over the fitted taus ([`floor`]) / √(2 ln2/π).
//!
//! A value the model does not have (no white share, no walk, no floor) is NaN:
//! not resolved, never 0. Uncertainties: the gradient of each value in the
//! terms' coordinates by central differences, through the covariance of the
//! free ones.

use super::basis::FLICKER_FACTOR;
use super::filter::OutputFilter;
use super::term::Term;
use super::{allan_terms, offsets};

/// Points of the log-spaced grid over the fitted taus on which B's floor is sought.
const FLOOR_GRID: usize = 200;

/// A curve whose log-log slope is above this has flattened: a minimum at its end
/// is a bias-instability floor (slope −½ is white noise, 0 the floor).
pub const FLAT_SLOPE: f64 = -0.25;

/// Relative step of the central differences in a variance; the same absolute
/// step in a logarithm or a skew.
const STEP: f64 = 1e-4;

/// The datasheet quantities, in the order of [`Datasheet::ALL`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Datasheet {
    N,
    B,
    K,
}

impl Datasheet {
    pub const ALL: [Datasheet; 3] = [Datasheet::N, Datasheet::B, Datasheet::K];

    pub fn name(self) -> &'static str {
        match self {
            Datasheet::N => "N",
            Datasheet::B => "B",
            Datasheet::K => "K",
        }
    }
}

/// A datasheet value and its standard uncertainty (NaN where not resolved).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Value {
    pub value: f64,
    pub std: f64,
}

/// What a datasheet value is read from: the model's terms, the fitted taus, the
/// record's duration (s; a Gauss–Markov term stands in for K only if its hump lies
/// beyond it), the sample rate and the output filter.
pub struct Model<'a> {
    pub terms: &'a [Term],
    pub taus: &'a [f64],
    pub record: f64,
    pub fs: f64,
    pub filter: Option<&'a OutputFilter>,
}

/// (τ, σ) of the floor of the model's deviation over the fitted taus, where B is
/// read; None where the curve has none.
///
/// The floor is the curve's minimum. Where that minimum is the last tau and the
/// curve still falls there (slope below [`FLAT_SLOPE`]), it is the lowest valley
/// of the curve (where its slope turns from falling to rising), else the lowest
/// point of its flat parts: a slow Gauss–Markov bump beyond a flat bottom falls
/// again past its peak, and the bottom before it is the floor a reader sees. A
/// curve that never flattens after falling has none. A rising head at the
/// shortest taus (an output filter's) is no floor either way. Tones and
/// resonances are left out of that search: a tone's comb has a zero at every
/// period.
pub fn floor(model: &Model) -> Option<(f64, f64)> {
    let (lo, hi) = (model.taus[0], model.taus[model.taus.len() - 1]);
    let grid: Vec<f64> = if hi > lo {
        (0..FLOOR_GRID)
            .map(|i| lo * (hi / lo).powf(i as f64 / (FLOOR_GRID - 1) as f64))
            .collect()
    } else {
        vec![lo]
    };
    let curve = |terms: &[Term]| -> Vec<f64> {
        (allan_terms(&grid, model.fs, terms, model.filter).iter())
            .map(|row| row.iter().sum::<f64>().sqrt())
            .collect()
    };
    let dev = curve(model.terms);
    let argmin = |v: &[f64], ok: &dyn Fn(usize) -> bool| -> Option<usize> {
        (0..v.len())
            .filter(|&i| ok(i) && !v[i].is_nan())
            .min_by(|&a, &b| v[a].total_cmp(&v[b]))
    };
    // The head before the curve first falls is no floor: an output filter
    // lowers the shortest taus, and the curve rises from there to its top.
    let n = grid.len();
    let head = (1..n).find(|&k| dev[k] < dev[k - 1]).map_or(0, |k| k - 1);
    let mut i = argmin(&dev, &|k| k >= head)?;
    if n >= 2 && i == n - 1 {
        let end_slope = (dev[n - 1] / dev[n - 2]).ln() / (grid[n - 1] / grid[n - 2]).ln();
        if end_slope < FLAT_SLOPE {
            let smooth_terms: Vec<Term> = (model.terms.iter())
                .filter(|t| !matches!(t, Term::Tone { .. } | Term::Resonance { .. }))
                .copied()
                .collect();
            let smooth = curve(&smooth_terms);
            let log_s: Vec<f64> = smooth.iter().map(|v| v.ln()).collect();
            let log_t: Vec<f64> = grid.iter().map(|t| t.ln()).collect();
            let slope: Vec<f64> = (0..n)
                .map(|k| {
                    let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
                    (log_s[b] - log_s[a]) / (log_t[b] - log_t[a])
                })
                .collect();
            let mut fallen = false;
            let flat: Vec<bool> = (slope.iter())
                .map(|&s| {
                    fallen |= s < FLAT_SLOPE;
                    s >= FLAT_SLOPE && fallen
                })
                .collect();
            if !flat.iter().any(|&f| f) {
                return None;
            }
            let valley: Vec<bool> = (0..n)
                .map(|k| k > 0 && slope[k - 1] < 0.0 && slope[k] >= 0.0)
                .collect();
            let pick = if valley.iter().any(|&v| v) {
                &valley
            } else {
                &flat
            };
            i = argmin(&smooth, &|k| pick[k])?;
        }
    }
    Some((grid[i], dev[i]))
}

/// The value of `which` for `model`; NaN where not resolved.
pub fn value(which: Datasheet, model: &Model) -> f64 {
    let total: f64 = match which {
        Datasheet::B => {
            return floor(model).map_or(f64::NAN, |(_, dev)| dev / FLICKER_FACTOR.sqrt());
        }
        Datasheet::N => model.terms.iter().map(|t| t.white_share(model.fs)).sum(),
        Datasheet::K => model.terms.iter().map(|t| t.walk_share(model.record)).sum(),
    };
    if total > 0.0 {
        total.sqrt()
    } else {
        f64::NAN
    }
}

/// The value of `which` and its standard uncertainty: the gradient in the
/// terms' coordinates (central differences) through `cov`, the covariance of
/// those coordinates term after term ([`super::NoiseFit::cov`]), over the
/// coordinates with a positive variance (one on a bound has none).
pub fn propagated(which: Datasheet, model: &Model, cov: &[Vec<f64>]) -> Value {
    let v0 = value(which, model);
    if v0.is_nan() || v0 <= 0.0 {
        return Value {
            value: v0,
            std: f64::NAN,
        };
    }
    let starts = offsets(model.terms);
    let mut active: Vec<usize> = Vec::new();
    let mut grad: Vec<f64> = Vec::new();
    for (k, term) in model.terms.iter().enumerate() {
        let x = term.coordinates();
        let names = term.kind().coordinate_names();
        for j in 0..x.len() {
            let at = starts[k] + j;
            let variance = cov.get(at).and_then(|r| r.get(at)).copied();
            if !variance.is_some_and(|v| v > 0.0) {
                continue;
            }
            let (up, down) = match names[j] {
                "skew" => ((x[j] + STEP).min(1.0), (x[j] - STEP).max(-1.0)),
                name if name.starts_with("ln_") => (x[j] + STEP, x[j] - STEP),
                _ => (x[j] * (1.0 + STEP), (x[j] * (1.0 - STEP)).max(0.0)),
            };
            let moved = |c: f64| {
                let mut y = x.clone();
                y[j] = c;
                let mut terms = model.terms.to_vec();
                match Term::from_coordinates(term.kind(), &y) {
                    Ok(t) => terms[k] = t,
                    Err(_) => return f64::NAN,
                }
                value(
                    which,
                    &Model {
                        terms: &terms,
                        ..*model
                    },
                )
            };
            active.push(at);
            grad.push((moved(up) - moved(down)) / (up - down));
        }
    }
    let mut var = 0.0;
    for (a, &i) in active.iter().enumerate() {
        for (b, &j) in active.iter().enumerate() {
            var += grad[a] * cov[i][j] * grad[b];
        }
    }
    Value {
        value: v0,
        std: var.max(0.0).sqrt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model<'a>(terms: &'a [Term], taus: &'a [f64]) -> Model<'a> {
        Model {
            terms,
            taus,
            record: 10.0 * taus[taus.len() - 1],
            fs: 100.0,
            filter: None,
        }
    }

    #[test]
    fn a_bump_within_the_record_is_not_k_and_one_beyond_it_is() {
        let taus = [0.01, 1000.0];
        let bump = [
            Term::White { variance: 1e-6 },
            Term::GaussMarkov {
                variance: 1e-8,
                tau_c: 20.0,
            },
        ];
        assert!(value(Datasheet::K, &model(&bump, &taus)).is_nan());
        // its hump (3.8e3 s) beyond the longest tau but within the record (10⁴ s)
        let slow = [
            Term::White { variance: 1e-6 },
            Term::GaussMarkov {
                variance: 1e-8,
                tau_c: 2000.0,
            },
        ];
        assert!(value(Datasheet::K, &model(&slow, &taus)).is_nan());
        let slow = [
            Term::White { variance: 1e-6 },
            Term::GaussMarkov {
                variance: 1e-8,
                tau_c: 6000.0,
            },
        ];
        let k = value(Datasheet::K, &model(&slow, &taus));
        assert!(
            (k / (2.0 * 1e-8 / 6000.0f64).sqrt() - 1.0).abs() < 1e-12,
            "{k}"
        );
    }

    #[test]
    fn a_gauss_markov_term_counts_in_n_only_past_its_hump() {
        let taus = [0.01, 1000.0];
        let white = Term::White { variance: 1e-6 };
        let n_with = |tau_c: f64| {
            let terms = [
                white,
                Term::GaussMarkov {
                    variance: 1e-4,
                    tau_c,
                },
            ];
            value(Datasheet::N, &model(&terms, &taus))
        };
        // a sensor filter's fast term: white at the 1 s read-off, in N
        assert!(n_with(0.01) > 1.1e-3, "{}", n_with(0.01));
        // a bump whose hump (1.89 s) lies beyond 1 s: a bias state, not N
        assert_eq!(n_with(1.0), 1e-3);
    }

    #[test]
    fn an_output_filters_head_is_no_floor() {
        // a 20-sample moving average lowers the shortest taus below the floor
        let taps = 20.0;
        let gain: Vec<f64> = (0..4097)
            .map(|k| {
                let nu = 0.5 * k as f64 / 4096.0;
                if k == 0 {
                    1.0
                } else {
                    let x = std::f64::consts::PI * nu;
                    ((taps * x).sin() / (taps * x.sin())).powi(2)
                }
            })
            .collect();
        let filter = OutputFilter::new(gain).unwrap();
        let taus = [0.01, 100.0];
        let terms = [
            Term::White { variance: 1e-6 },
            Term::Flicker { variance: 1e-8 },
            Term::RandomWalk { variance: 1e-6 },
        ];
        let unfiltered = floor(&model(&terms, &taus)).unwrap();
        let filtered = floor(&Model {
            filter: Some(&filter),
            ..model(&terms, &taus)
        })
        .unwrap();
        let head = allan_terms(&[0.01], 100.0, &terms, Some(&filter))[0]
            .iter()
            .sum::<f64>()
            .sqrt();
        assert!(
            head < filtered.1,
            "the head {head} is not below the floor {filtered:?}"
        );
        assert!(filtered.0 > 0.05, "floor at {} s", filtered.0);
        // past the head the filter lowers the white part a little
        let ratio = filtered.1 / unfiltered.1;
        assert!(ratio > 0.8 && ratio <= 1.0, "{filtered:?} {unfiltered:?}");
    }

    #[test]
    fn b_is_the_flat_minimum_over_the_flicker_factor() {
        let taus = [0.01, 1e4];
        let terms = [
            Term::White { variance: 1e-6 },
            Term::Flicker { variance: 4e-8 },
            Term::RandomWalk { variance: 1e-14 },
        ];
        let b = value(Datasheet::B, &model(&terms, &taus));
        // the minimum sits a little above the flicker floor (N and K add to it)
        assert!(b > 2e-4 && b < 2e-4 * 1.2, "{b}");
        let falling = [Term::White { variance: 1e-6 }];
        assert!(value(Datasheet::B, &model(&falling, &taus)).is_nan());
    }

    #[test]
    fn uncertainty_of_n_is_its_own_through_one_term() {
        let taus = [0.01, 100.0];
        let terms = [
            Term::White { variance: 4e-6 },
            Term::Flicker { variance: 1e-8 },
        ];
        let cov = vec![vec![1e-14, 0.0], vec![0.0, 1e-18]];
        let n = propagated(Datasheet::N, &model(&terms, &taus), &cov);
        // N = √v: u(N) = u(v)/(2N)
        assert!((n.value - 2e-3).abs() < 1e-15);
        assert!((n.std / (1e-7 / (2.0 * 2e-3)) - 1.0).abs() < 1e-6, "{n:?}");
    }
}
