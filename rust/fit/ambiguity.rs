//! What the chosen structure does not decide: a term whose part of the curve
//! another kind of term describes as well.
//!
//! The rise of the longest taus is a rate random walk (K²τ/3), a rate ramp
//! (R²τ²/2) or the near side of a slow Gauss–Markov bump, and on the last few,
//! nearly dependent estimates of a record these can fit about equally well. The
//! selection must pick one, but a datasheet value read off a structure the data
//! do not prefer is a guess: K taken from a ramp's rise is tens of times the
//! sensor's walk, and an estimator fed it inflates its bias process noise by as
//! much. Such a term is "not resolved" (its value NaN, its bound the largest the
//! curve allows) and the model says which alternative ties with it.

use super::estimate::Data;
use super::search::{self, Candidate};
use super::term::{Kind, GM_PEAK};
use super::{IEEE_TERMS, MAX_GM};

/// BIC difference below which the data do not prefer one structure to another:
/// 2, where "positive" evidence starts on Kass and Raftery's scale (JASA 90,
/// 1995; below it, "not worth more than a bare mention").
pub const DECISIVE: f64 = 2.0;

/// A datasheet term of the chosen structure that an alternative explains as well.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ambiguity {
    /// The term not resolved.
    pub kind: Kind,
    /// The kind of term that describes the same part of the curve instead; None
    /// where a structure without the term needs no other kind for it.
    pub alternative: Option<Kind>,
    /// The alternative structure's BIC minus the chosen one's (< [`DECISIVE`]).
    pub delta_bic: f64,
}

/// The terms of `chosen` (selected among the IEEE terms `allowed` and up to
/// `max_gm` Gauss–Markov terms) that an alternative structure fits with a BIC
/// less than [`DECISIVE`] higher: the random walk against a ramp in its place
/// and against one more Gauss–Markov term whose hump the fitted taus show; the
/// ramp against a walk in its place (these keep every other term of `chosen`);
/// and each against `without(j)`, the best structure found with IEEE term `j`
/// ([`search::WALK`] or [`search::RAMP`]) left out, sought only when the
/// alternatives before it do not tie. A walk and a ramp together are not
/// questioned by a swap: each then has a part of the curve the other does not
/// describe.
pub fn ambiguities(
    data: &Data,
    fs: f64,
    allowed: [bool; IEEE_TERMS],
    max_gm: usize,
    chosen: &Candidate,
    without: impl Fn(usize) -> Option<Candidate>,
) -> Vec<Ambiguity> {
    let (walk, ramp) = (search::WALK, search::RAMP);
    let in_use = |j: usize| chosen.ieee[j] && chosen.solution.theta[j] > 0.0;
    // An alternative that fits no positive curve is no alternative.
    let tie = |kind: Kind, alternative: Option<Kind>, other: Option<&Candidate>| {
        let delta_bic = other?.bic - chosen.bic;
        (delta_bic < DECISIVE).then_some(Ambiguity {
            kind,
            alternative,
            delta_bic,
        })
    };
    let reselected = |kind: Kind, j: usize| {
        let other = without(j)?;
        tie(kind, first_added(fs, chosen, &other), Some(&other))
    };
    let swapped = |off: usize, on: usize| {
        let mut ieee = chosen.ieee;
        ieee[off] = false;
        ieee[on] = true;
        search::rebuilt(data, fs, ieee, chosen).ok()
    };
    let found = match (in_use(walk), in_use(ramp)) {
        (true, false) => (allowed[ramp])
            .then(|| {
                let other = swapped(walk, ramp);
                tie(Kind::RandomWalk, Some(Kind::Ramp), other.as_ref())
            })
            .flatten()
            .or_else(|| {
                let bump = slow_bump(data, fs, max_gm, chosen);
                tie(Kind::RandomWalk, Some(Kind::GaussMarkov), bump.as_ref())
            })
            .or_else(|| reselected(Kind::RandomWalk, walk)),
        (false, true) => (allowed[walk])
            .then(|| {
                let other = swapped(ramp, walk);
                tie(Kind::Ramp, Some(Kind::RandomWalk), other.as_ref())
            })
            .flatten()
            .or_else(|| reselected(Kind::Ramp, ramp)),
        (true, true) => reselected(Kind::RandomWalk, walk).or_else(|| reselected(Kind::Ramp, ramp)),
        _ => None,
    };
    found.into_iter().collect()
}

/// The first kind, in the order of [`Kind::ALL`], of which `other` has more terms
/// than `chosen`: what describes instead the part of the curve a term of
/// `chosen` that `other` lacks took. None when `other` adds no kind.
fn first_added(fs: f64, chosen: &Candidate, other: &Candidate) -> Option<Kind> {
    let counts = |c: &Candidate| {
        let mut n = [0usize; Kind::ALL.len()];
        for t in c.terms(fs) {
            n[t.kind() as usize] += 1;
        }
        n
    };
    let (had, has) = (counts(chosen), counts(other));
    (Kind::ALL.into_iter()).find(|&kind| has[kind as usize] > had[kind as usize])
}

/// `chosen` with its walk (and any ramp it may have had room for) replaced by
/// one more Gauss–Markov term, the structure's other terms kept: the new term's
/// correlation time the best of [`search::time_grid`] among those whose hump
/// (GM_PEAK·τc) the fitted taus show (past the longest, it rises to the end like
/// the walk, and is one: the datasheet K counts it). None when the structure has
/// [`MAX_GM`] Gauss–Markov terms in use already, or no such time fits.
fn slow_bump(data: &Data, fs: f64, max_gm: usize, chosen: &Candidate) -> Option<Candidate> {
    let times = chosen.gm_in_use();
    if times.len() >= max_gm.min(MAX_GM) {
        return None;
    }
    let mut ieee = chosen.ieee;
    ieee[search::WALK] = false;
    ieee[search::RAMP] = false;
    let extras = (chosen.sine, chosen.resonance, chosen.motion);
    let longest = data.taus[data.len() - 1];
    (search::time_grid(data, fs).into_iter())
        .take_while(|&tau_c| GM_PEAK * tau_c <= longest)
        .filter_map(|tau_c| {
            let with = [times.as_slice(), &[tau_c]].concat();
            search::candidate(data, fs, ieee, with, extras, chosen.solution.d2).ok()
        })
        .min_by(|a, b| a.bic.total_cmp(&b.bic))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::search::Tones;

    fn grid(per_decade: f64, lo: f64, hi: f64) -> Vec<f64> {
        let n = ((hi / lo).log10() * per_decade).round() as usize;
        (0..=n)
            .map(|i| lo * 10f64.powf(i as f64 / per_decade))
            .collect()
    }

    fn data_for(curve: impl Fn(f64) -> f64, edf_scale: f64) -> (Vec<f64>, Data) {
        let fs = 100.0;
        let taus = grid(10.0, 0.01, 1000.0);
        let var: Vec<f64> = taus.iter().map(|&t| curve(t)).collect();
        let edf: Vec<f64> = taus.iter().map(|&t| edf_scale * 3600.0 / t).collect();
        let data = Data::new(&taus, &var, &edf, fs).unwrap();
        (taus, data)
    }

    #[test]
    fn a_walk_seen_over_decades_is_not_questioned() {
        let n = 1e-3f64;
        let k = 4e-5f64;
        let (_, data) = data_for(|t| n * n / t + k * k * t / 3.0, 1.0);
        let ieee = [false, true, true, true, true];
        let chosen = search::select(&data, 100.0, ieee, 0, (0, false, false)).unwrap();
        assert!(chosen.solution.theta[3] > 0.0);
        assert!(ambiguities(&data, 100.0, ieee, 0, &chosen, |_| None).is_empty());
    }

    #[test]
    fn a_walk_the_last_taus_barely_show_ties_with_a_ramp() {
        // White noise with a walk that reaches the curve only at the last tau or
        // two, from estimates of a few degrees of freedom: a ramp fits as well.
        let n = 1e-3f64;
        let k = 2e-6f64;
        let (_, data) = data_for(|t| n * n / t + k * k * t / 3.0, 1.0);
        let ieee = [false, true, false, true, true];
        let walk = search::candidate(
            &data,
            100.0,
            [false, true, false, true, false],
            Vec::new(),
            (Tones::NONE, None, None),
            0.0,
        )
        .unwrap();
        assert!(walk.solution.theta[3] > 0.0);
        let found = ambiguities(&data, 100.0, ieee, 0, &walk, |_| None);
        assert!(
            found
                .iter()
                .any(|a| a.kind == Kind::RandomWalk && a.alternative == Some(Kind::Ramp)),
            "{found:?}"
        );
        assert!(found.iter().all(|a| a.delta_bic < DECISIVE));
    }
}
