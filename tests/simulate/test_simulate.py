"""The simulator: each term's Allan deviation against the IEEE 952 closed forms.

Oracle: allantools' overlapping ADEV (a peer implementation), averaged over a
few seeds, against σ(τ) of each term alone.
"""

from __future__ import annotations

import math

import allantools
import imunoise
import numpy as np
import pytest
from imunoise.noise import model_variance

FS = 40.0


@pytest.mark.parametrize(
    ("term", "value", "tol"),
    [("N", 1e-3, 0.03), ("B", 1e-4, 0.08), ("K", 1e-5, 0.08), ("Q", 1e-4, 0.02),
     ("R", 1e-6, 1e-6)],
)
def test_each_term_has_its_closed_form(term, value, tol):
    taus = np.array([0.1, 1.0, 10.0, 100.0])
    var = []
    for seed in range(4):
        y = imunoise.simulate(200_000, FS, seed=seed, **{term: value})
        _, d, _, _ = allantools.oadev(y, rate=FS, data_type="freq", taus=taus)
        var.append(d**2)
    dev = np.sqrt(np.mean(var, axis=0))
    expect = np.sqrt(model_variance(taus, **{term: value}))
    np.testing.assert_allclose(dev, expect, rtol=tol)


def test_flicker_flat_level_is_0_6643_b():
    b = 2e-4
    y = imunoise.simulate(400_000, FS, B=b, seed=9)
    _, d, _, _ = allantools.oadev(y, rate=FS, data_type="freq", taus=np.array([1.0, 10.0]))
    assert d / b == pytest.approx([math.sqrt(2 * math.log(2) / math.pi)] * 2, rel=0.08)


def test_shapes_and_seed():
    a = imunoise.simulate(1000, 10.0, N=1.0, K=0.1, channels=3, seed=4)
    b = imunoise.simulate(1000, 10.0, N=1.0, K=0.1, channels=3, seed=4)
    assert a.shape == (1000, 3) and a.dtype == np.float64
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a[:, 0], a[:, 1])  # channels are independent
    assert imunoise.simulate(5, 1.0).shape == (5,)
    assert not np.any(imunoise.simulate(5, 1.0))


def test_long_flicker_is_chunked_consistently():
    """Blocks of the overlap-save flicker join without a seam (small block size)."""
    from imunoise._simulation.simulate import flicker

    rng = np.random.default_rng(0)
    y = flicker(1 << 14, 1.0, rng, taps=1 << 10)
    steps = np.diff(y)
    seams = steps[(1 << 10) - 1 :: 1 << 10]
    assert np.std(seams) == pytest.approx(np.std(steps), rel=0.3)


def test_old_call_forms_warn_and_give_the_same_samples():
    new = imunoise.simulate(200, 10.0, 0.0, 1.0, channels=2, seed=3)
    with pytest.warns(DeprecationWarning, match=r"simulate\(n=...\) is deprecated"):
        np.testing.assert_array_equal(
            imunoise.simulate(n=200, fs=10.0, N=1.0, channels=2, seed=3), new
        )
    with pytest.warns(DeprecationWarning, match="channels, seed to simulate"):
        np.testing.assert_array_equal(
            imunoise.simulate(200, 10.0, 0.0, 1.0, 0.0, 0.0, 0.0, 2, 3), new
        )
    with pytest.raises(TypeError, match="both 'n_samples' and its old name 'n'"):
        imunoise.simulate(n_samples=10, fs=1.0, n=10)
    with pytest.raises(TypeError, match="at most 9 positional"):
        imunoise.simulate(10, 1.0, 0, 0, 0, 0, 0, 1, None, ())


def test_sample_rate_checks():
    for fs in (0.0, -5, float("nan"), float("inf")):
        with pytest.raises(ValueError, match=r"fs must be positive and finite \(Hz\)"):
            imunoise.simulate(10, fs)
    for fs in ("100", None, True):
        with pytest.raises(TypeError, match="fs must be a real number of Hz"):
            imunoise.simulate(10, fs)
    assert imunoise.simulate(3, np.float32(2.0)).shape == (3,)
