"""Noise-model fit: recovery of known coefficients from simulated data.

Oracle: the coefficients put into the simulator (whose Allan variance is the
IEEE 952 model by construction, checked term by term against allantools in
test_simulate.py), and the closed forms of the model for the slope read-off.
"""

from __future__ import annotations

import warnings

import imunoise
import numpy as np
import pytest
from helpers.noise_fit import StandInResult, allan
from hypothesis import given, settings
from hypothesis import strategies as st
from imunoise.noise import FLICKER, model_variance

FS = 40.0
HOURS5 = int(5 * 3600 * FS)


def _exact_result(taus, edf=1000.0, **coef):
    var = model_variance(taus, **coef)
    taus = np.asarray(taus)
    n = 10**9 - 2 * np.rint(taus * FS).astype(int)
    return StandInResult(kind="adev", overlapping=True, taus=taus, dev=np.sqrt(var), var=var,
                         n=n, edf=np.full(len(taus), edf), alpha=np.zeros(len(taus), dtype=int),
                         fs=FS)


@pytest.fixture(scope="module")
def vn_like():
    """Three axes of 5 h at 40 Hz with N, B, K (and their truth)."""
    truth = {"N": 2e-4, "B": 3e-5, "K": 2e-6}
    x = imunoise.simulate(HOURS5, FS, channels=3, seed=11, **truth)
    return truth, allan(x, FS)


@pytest.mark.parametrize(
    ("term", "value", "n", "tol"),
    [
        ("N", 1e-3, HOURS5 // 4, 0.03),
        ("B", 1e-4, HOURS5 // 2, 0.15),
        ("K", 1e-5, HOURS5 // 4, 0.30),
        ("Q", 1e-4, HOURS5 // 8, 0.03),
        ("R", 1e-6, HOURS5 // 8, 1e-3),  # deterministic: only the log-bias shift
    ],
)
def test_single_term_recovered_and_others_unsupported(term, value, n, tol):
    x = imunoise.simulate(n, FS, seed=3, **{term: value})
    model = imunoise.fit(allan(x, FS))
    est = float(getattr(model.components, term))
    assert model.components.supported[term]
    assert abs(est / value - 1) < tol, (term, est, value)
    # The reported uncertainty is honest (within 4 sigma) unless the term is exact.
    std = float(getattr(model.components, term + "_std"))
    assert np.isfinite(std)
    assert abs(est - value) <= 4 * std + 1e-9 * value
    # White noise alone must not produce a bias instability or a random walk.
    if term == "N":
        assert not model.components.supported["B"] and float(model.components.B) == 0.0
        assert not model.components.supported["K"] and float(model.components.K) == 0.0
        assert not model.components.supported["Q"] and not model.components.supported["R"]


def test_all_terms_together(vn_like):
    truth, result = vn_like
    model = imunoise.fit(result)
    assert model.components.N.shape == (3,)
    for term, tol in (("N", 0.02), ("B", 0.25)):
        est = model.components.value(term)
        assert np.sum(model.components.supported[term]) >= 2, term
        rel = np.abs(est / truth[term] - 1)
        assert np.median(rel) < tol, (term, est, truth[term])
    # A flicker realisation can look like a Gauss–Markov bump: the flat part is
    # always carried by one of the two.
    for c in range(3):
        assert model.components.supported["B"][c] or model.components.gauss_markov(c), c
    # At long tau a random-walk realisation can look like a ramp: on every axis
    # the long-tau rise is carried by K or R, never by nothing.
    assert np.all(model.components.supported["K"] | model.components.supported["R"])
    assert np.sum(model.components.supported["K"]) >= 2
    # Without the ramp term, K itself is recovered.
    nbk = imunoise.fit(result, terms=("N", "B", "K"))
    assert np.all(nbk.components.supported["K"])
    assert np.median(np.abs(nbk.components.K / truth["K"] - 1)) < 0.4
    # uncertainties assume independent taus; overlapping octaves correlate (docs/noise.md)
    assert np.all(np.abs(nbk.components.K - truth["K"]) < 5 * nbk.components.K_std)


def test_tau_ranges_follow_the_slopes(vn_like):
    truth, result = vn_like
    model = imunoise.fit(result)
    n_lo, n_hi = model.components.tau_range["N"][0]
    k_lo, k_hi = model.components.tau_range["K"][0]
    assert n_lo == result.taus[0]
    assert n_hi < k_lo  # white noise dominates short taus, the random walk long ones
    assert k_hi == result.taus[-1]


def test_predict_is_the_model(vn_like):
    _, result = vn_like
    model = imunoise.fit(result)
    taus = np.logspace(-2, 4, 13)
    p = model.predict(taus)
    assert p.dev.shape == (13, 3)
    parts = sum(v**2 for v in p.terms.values())
    np.testing.assert_allclose(p.dev**2, parts, rtol=1e-12)
    for c in range(3):
        expect = model_variance(taus, **{k: float(model.components.value(k)[c]) for k in "QNBKR"})
        gm = sum(p.terms[k][:, c] ** 2 for k in p.terms if k.startswith("GM"))
        np.testing.assert_allclose(p.dev[:, c] ** 2, expect + gm, rtol=1e-12)
    parts = model.components
    np.testing.assert_allclose(p.terms["N"][:, 0], parts.N[0] / np.sqrt(taus), rtol=1e-12)
    np.testing.assert_allclose(p.terms["B"][:, 1], FLICKER * model.components.B[1], rtol=1e-12)


def test_one_channel_shapes():
    x = imunoise.simulate(20000, FS, N=1e-3, seed=1)
    model = imunoise.fit(allan(x, FS))
    assert np.ndim(model.components.N) == 0 and model.channels == 1
    assert model.predict([1.0, 2.0]).dev.shape == (2,)
    assert model.kind == "adev" and model.fs == FS


def test_terms_restrict_the_model(vn_like):
    _, result = vn_like
    model = imunoise.fit(result, terms=("N", "K"))
    assert not np.any(model.components.supported["B"]) and np.all(model.components.B == 0)
    assert np.all(model.components.supported["N"])


def test_tau_range_restricts_the_fit(vn_like):
    _, result = vn_like
    model = imunoise.fit(result, tau_range=(0.0, 1.0))
    assert model.taus.max() <= 1.0
    assert not np.any(model.components.supported["K"])  # K is invisible below 1 s


def test_model_is_frozen(vn_like):
    _, result = vn_like
    model = imunoise.fit(result)
    with pytest.raises(AttributeError):
        model.components.N = 0
    with pytest.raises(ValueError):
        model.components.N[0] = 1.0


# -- slope read-off ----------------------------------------------------------

TAUS = np.logspace(-2, 5, 71)


@pytest.mark.parametrize("term", ["Q", "N", "B", "K", "R"])
def test_slopes_exact_on_single_term_curves(term):
    """On a pure power law the IEEE read-off is exact (closed forms)."""
    model = imunoise.fit(_exact_result(TAUS, **{term: 2.5e-3}), method="slopes")
    assert float(getattr(model.components, term)) == pytest.approx(2.5e-3, rel=1e-9)
    for other in "QNBKR":
        if other != term and other != "B":
            assert not model.components.supported[other], other


def test_slopes_on_vn100_like_curve():
    """N, B, K of a realistic curve: the read-off is close but biased (overlap)."""
    coef = {"N": 6e-5, "B": 2.4e-5, "K": 1e-6}
    slopes = imunoise.fit(_exact_result(TAUS, **coef), method="slopes")
    wls = imunoise.fit(_exact_result(TAUS, **coef), method="wls")
    for k, v in coef.items():
        assert float(getattr(slopes, k)) == pytest.approx(v, rel=0.25), k
        # exact curves carry no χ² scatter; the fit's log-bias correction for
        # edf = 1000 (E ln χ²/ν ≈ −1/ν) shifts them by ~1e-3
        assert float(getattr(wls.components, k)) == pytest.approx(v, rel=3e-3), k
    # B from the flat part: sigma_min / 0.6643, never 0.6643 * sigma^2
    dev = np.sqrt(model_variance(TAUS, **coef))
    assert float(slopes.B) >= dev.min() / FLICKER * 0.99


def test_slopes_matches_matlab_rule_by_hand():
    """N: line of slope -1/2 through the point of closest slope, read at tau=1."""
    coef = {"N": 1e-3, "K": 1e-5}
    r = _exact_result(TAUS, **coef)
    model = imunoise.fit(r, method="slopes")
    logt, logd = np.log10(r.taus), np.log10(r.dev)
    s = np.diff(logd) / np.diff(logt)
    i = np.argmin(np.abs(s + 0.5))
    by_hand = 10 ** (logd[i] + 0.5 * logt[i])
    assert float(model.components.N) == pytest.approx(by_hand, rel=1e-12)
    j = np.argmin(np.abs(s - 0.5))
    by_hand_k = 10 ** (logd[j] - 0.5 * logt[j] + 0.5 * np.log10(3.0))
    assert float(model.components.K) == pytest.approx(by_hand_k, rel=1e-12)


def test_wls_agrees_with_allan_variance_on_an_exact_curve():
    """Peer cross-check: on an exact model curve both NNLS fits return the truth."""
    allan_variance = pytest.importorskip("allan_variance")
    coef = {"Q": 3e-6, "N": 6e-5, "B": 2.4e-5, "K": 1e-6, "R": 1e-8}
    r = _exact_result(TAUS, **coef)
    ours = imunoise.fit(r)
    params, _ = allan_variance.estimate_parameters(r.taus, r.var)
    names = {"Q": "quantization", "N": "white", "B": "flicker", "K": "walk", "R": "ramp"}
    for k, v in coef.items():
        assert float(getattr(ours.components, k)) == pytest.approx(v, rel=3e-3), k
        assert float(getattr(ours.components, k)) == pytest.approx(params[names[k]], rel=3e-3), k


@pytest.fixture(scope="module")
def vn_like_small():
    x = imunoise.simulate(200_000, FS, N=2e-4, B=3e-5, K=4e-6, channels=2, seed=2)
    return allan(x, FS)


@settings(max_examples=15, deadline=None)
@given(st.floats(1e-6, 1e6), st.sampled_from(["wls", "slopes"]))
def test_fit_is_scale_equivariant(vn_like_small, scale, method):
    """Scaling the data by c scales every coefficient and uncertainty by c."""
    r = vn_like_small
    scaled = StandInResult(kind="adev", overlapping=True, taus=r.taus, dev=r.dev * scale,
                           var=r.var * scale**2, n=r.n, edf=r.edf, alpha=r.alpha, fs=r.fs)
    a = imunoise.fit(r, method=method)
    b = imunoise.fit(scaled, method=method)
    for k in "QNBKR":
        np.testing.assert_array_equal(a.supported[k], b.supported[k])
        np.testing.assert_allclose(b.value(k), scale * a.value(k), rtol=1e-6)
        np.testing.assert_allclose(b.std(k), scale * a.std(k), rtol=1e-5)


# --- parametric bootstrap uncertainties -------------------------------------------------


@pytest.mark.parametrize("truth", [{"N": 1e-3}, {"N": 1e-3, "K": 1e-4}])
def test_bootstrap_std_matches_the_spread_of_repeated_experiments(truth):
    # Oracle: 40 independent records of the true noise, fitted like the data; their
    # spread is what an uncertainty should describe. The bootstrap sees one record.
    # Tolerances: ~11 % sampling error on each spread; K's bootstrap also scales with
    # the one record's K estimate. The independent-taus std is ~0.75 of the spread
    # for N here, outside N's band.
    fs, n = 50.0, 20_000
    opts = {"terms": tuple(truth)}
    repeated = np.array([
        [imunoise.fit(imunoise.adev(imunoise.simulate(n, fs, seed=s, **truth), fs),
                      **opts).value(t)[0] for t in truth]
        for s in range(100, 140)
    ])
    spread = repeated.std(axis=0, ddof=1)
    x = imunoise.simulate(n, fs, seed=7, **truth)
    model = imunoise.fit(imunoise.adev(x, fs), uncertainty="bootstrap", replicates=40, seed=3,
                         **opts)
    bands = {"N": (0.82, 1.25), "K": (0.6, 1.6)}
    for i, term in enumerate(truth):
        ratio = model.components.std(term)[0] / spread[i]
        assert bands[term][0] < ratio < bands[term][1], (term, ratio)


def test_bootstrap_is_reproducible_and_keeps_unsupported_terms_nan():
    x = imunoise.simulate(20_000, 50.0, N=1e-3, seed=2)
    r = imunoise.adev(x, 50.0)
    a = imunoise.fit(r, uncertainty="bootstrap", replicates=10, seed=5)
    b = imunoise.fit(r, uncertainty="bootstrap", replicates=10, seed=5)
    c = imunoise.fit(r, uncertainty="bootstrap", replicates=10, seed=6)
    assert a.N_std == b.N_std and a.N_std != c.N_std
    assert a.N == imunoise.fit(r).N  # the estimate itself does not change
    assert not a.supported["R"] and np.isnan(a.R_std)


def test_bootstrap_on_several_channels_and_non_overlapping_adev():
    x = imunoise.simulate(12_000, 20.0, N=1e-3, channels=2, seed=4)
    x[:, 1] *= 10.0
    r = imunoise.adev(x, 20.0, overlapping=False)
    model = imunoise.fit(r, uncertainty="bootstrap", replicates=12, seed=1)
    assert model.components.N_std.shape == (2,)
    n_std = model.components.N_std
    np.testing.assert_allclose(n_std[1] / n_std[0], 10.0, rtol=0.6)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"uncertainty": "mc"}, ValueError, "uncertainty must be 'independent' or 'bootstrap'"),
        ({"uncertainty": "bootstrap", "replicates": 2}, ValueError, "replicates must be >= 5"),
        ({"uncertainty": "bootstrap", "replicates": 7.5}, TypeError, "replicates must be an"),
        # 10**9 replicates tried to allocate 1.19 TiB at once
        ({"uncertainty": "bootstrap", "replicates": 10**9}, ValueError,
         "replicates must be at most 100,000 for a record of 2,000 samples"),
    ],
)
def test_bootstrap_bad_arguments(kwargs, error, match):
    r = imunoise.adev(imunoise.simulate(2000, 10.0, N=1e-3, seed=1), 10.0)
    with pytest.raises(error, match=match):
        imunoise.fit(r, **kwargs)


def test_a_sparse_grid_warns_when_the_model_has_components_it_places_poorly():
    x = imunoise.simulate(200_000, 100.0, N=1e-4, B=2e-5, gm=[(1e-4, 0.05)], seed=1)
    with pytest.warns(UserWarning, match=r"3\.3 taus per decade.*taus=10"):
        octave = imunoise.fit(imunoise.adev(x, 100.0))
    assert octave.components.gauss_markov()  # the premise: a component was fitted
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        imunoise.fit(imunoise.adev(x, 100.0, taus=10))
    # IEEE terms alone are no reason to warn, whatever the grid.
    plain = imunoise.simulate(200_000, 100.0, N=1e-4, seed=2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        imunoise.fit(imunoise.adev(plain, 100.0), terms=["N"])
