"""EDF where phase noise begins beyond the first tau: a bounded motion (an AR1
angle whose rate is recorded) looks like white FM below its correlation time and
white PM beyond it. Greenhall's white-PM EDF counts every phase point as a draw
and overstated the EDF a thousandfold there; the phase points are now counted a
corner apart. Judged against the Monte Carlo spread of the estimates."""

import warnings

import imunoise
import numpy as np

FS = 100.0
N = 60_000
TAU_C = 5.0


def _replicates(count=48):
    out = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for seed in range(count):
            x = imunoise.simulate(N, FS, N=1e-6, seed=seed, motion=(1e-3, TAU_C))
            out.append(imunoise.adev(x, FS, taus=5))
    return out


def test_reported_edf_follows_the_monte_carlo_spread_beyond_the_corner():
    reps = _replicates()
    taus = reps[0].taus
    var = np.array([r.var.ravel() for r in reps])
    reported = np.median([r.edf.ravel() for r in reps], axis=0)
    alpha = np.median([np.ravel(r.alpha) for r in reps], axis=0)
    empirical = 2 * var.mean(0) ** 2 / var.var(0, ddof=1)
    bounded = (alpha >= 2) & (taus >= 2 * TAU_C) & (taus <= N / FS / 10)
    assert bounded.sum() >= 3, alpha
    ratio = reported[bounded] / empirical[bounded]
    # The Monte Carlo EDF of 48 replicates is itself uncertain by ~±20 %.
    assert np.all((ratio > 1 / 3) & (ratio < 3)), (taus[bounded], reported[bounded],
                                                  empirical[bounded])


def test_white_phase_from_the_first_tau_keeps_greenhalls_count():
    rng = np.random.default_rng(4)
    x = np.diff(rng.standard_normal(N + 1))  # white PM as a rate
    r = imunoise.adev(x, FS, taus=5)
    assert np.all(np.ravel(r.alpha)[np.ravel(r.alpha_identified)] >= 2)
    # Greenhall's white-PM EDF is about N/2 at every tau well below N/10.
    short = r.taus <= N / FS / 100
    assert np.all(r.edf.ravel()[short] > N / 4)
