"""Bad inputs to fit/simulate give clear errors naming the argument."""

from __future__ import annotations

import imunoise
import numpy as np
import pytest
from helpers.noise_fit import StandInResult
from hypothesis import example, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp


def _result(taus, var, edf=None, kind="adev"):
    taus = np.asarray(taus, dtype=float)
    var = np.asarray(var, dtype=float)
    edf = np.full(var.shape, 10.0) if edf is None else np.asarray(edf, dtype=float)
    return StandInResult(kind=kind, overlapping=True, taus=taus, dev=np.sqrt(np.abs(var)),
                         var=var, n=np.ones(taus.shape, dtype=int), edf=edf,
                         alpha=np.zeros(var.shape, dtype=int), fs=10.0)


def test_empty_result():
    with pytest.raises(ValueError, match="result.taus"):
        imunoise.fit(_result([], []))


def test_single_tau():
    with pytest.raises(ValueError, match="at least 2"):
        imunoise.fit(_result([1.0], [1e-4]))


def test_all_nan():
    with pytest.raises(ValueError, match="no usable tau"):
        imunoise.fit(_result([1.0, 2.0, 4.0], [np.nan] * 3))


def test_wrong_kind_and_type():
    with pytest.raises(ValueError, match="result.kind"):
        imunoise.fit(_result([1.0, 2.0], [1.0, 0.5], kind="mdev"))
    with pytest.raises(TypeError, match="result"):
        imunoise.fit(np.ones(3))


def test_bad_options():
    r = _result([1.0, 2.0, 4.0], [1.0, 0.5, 0.25])
    with pytest.raises(ValueError, match="method"):
        imunoise.fit(r, method="lsq")
    with pytest.raises(ValueError, match="terms"):
        imunoise.fit(r, terms=("N", "W"))
    with pytest.raises(ValueError, match="tau_range"):
        imunoise.fit(r, tau_range=(10.0, 20.0))
    with pytest.raises(ValueError, match="tau_range"):
        imunoise.fit(r, tau_range=(5.0, 1.0))


@settings(max_examples=60, deadline=None)
@given(
    hnp.arrays(np.float64, st.integers(0, 12),
               elements=st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                                  st.floats(1e-30, 1e30))),
    st.sampled_from(["wls", "slopes"]),
)
@example(np.array([7.93270207e307, 7.93270207e307]), "slopes")  # K² overflowed a float
@example(np.array([7.932702075510204e307, 7.932702075510204e307]), "slopes")  # and B²
def test_arbitrary_variances_never_crash(var, method):
    """Any variance vector either fits (each value finite and > 0, or NaN with a
    non-negative bound or none) or raises ValueError."""
    taus = 0.1 * 2.0 ** np.arange(var.size)
    try:
        m = imunoise.fit(_result(taus, var), method=method)
    except ValueError as exc:
        assert "result" in str(exc)
        return
    for k in "QNBKR":
        v = float(getattr(m, k))
        if m.resolved(k)[0]:
            assert np.isfinite(v) and v > 0
        else:
            assert np.isnan(v)
            assert not float(m.upper[k]) < 0


@pytest.mark.parametrize(
    ("kwargs", "exc", "word"),
    [
        ({"n_samples": 0}, ValueError, "n_samples must"),
        ({"n_samples": 1.5}, TypeError, "n_samples must"),
        ({"fs": 0.0}, ValueError, "fs must"),
        ({"fs": np.nan}, ValueError, "fs must"),
        ({"N": -1.0}, ValueError, "N must"),
        ({"B": np.inf}, ValueError, "B must"),
        ({"K": "x"}, TypeError, "K must"),
        ({"channels": 0}, ValueError, "channels must"),
    ],
)
def test_simulate_errors(kwargs, exc, word):
    args = {"n_samples": 10, "fs": 1.0} | kwargs
    with pytest.raises(exc, match=word):
        imunoise.simulate(**args)
