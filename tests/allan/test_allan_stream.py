"""The Allan deviation of a stream, fed block by block: at any moment the same curve as
imunoise.adev on the samples so far, with an offset kept to its digits."""

from __future__ import annotations

import warnings

import imunoise
import numpy as np
import pytest

FS = 100.0


def test_every_moment_equals_adev_of_the_samples_so_far():
    x = imunoise.simulate(60_000, FS, N=1e-3, K=1e-5, channels=3, seed=1) + [9.81, 0.0, -3.0]
    stream = imunoise.AllanStream(FS, channels=3)
    edges = np.cumsum(np.random.default_rng(2).integers(1, 5000, size=40))
    edges = edges[edges < len(x)]
    for a, b in zip(np.r_[0, edges], np.r_[edges, len(x)], strict=True):
        stream.update(x[a:b])
        if b < 16:
            continue
        got, want = stream.result(), imunoise.adev(x[:b], FS, taus="octave")
        k = min(len(got.taus), len(want.taus))
        assert k >= len(want.taus) - 1
        np.testing.assert_array_equal(got.m[:k], want.m[:k])
        np.testing.assert_array_equal(got.n[:k], want.n[:k])
        np.testing.assert_allclose(got.dev[:k], want.dev[:k], rtol=1e-12)
    assert stream.n_samples == len(x)
    assert got.ci_low.shape == got.dev.shape and np.all(got.ci_low < got.dev)


def test_the_longest_tau_is_bounded_and_one_channel_is_one_dimensional():
    stream = imunoise.AllanStream(FS, max_tau=1.0)
    stream.update(imunoise.simulate(10_000, FS, N=1e-3, seed=3))
    r = stream.result()
    assert r.dev.ndim == 1 and r.taus[-1] <= 1.0 and r.taus[-1] == 0.64
    assert "AllanStream(1 channel at 100 Hz; 10,000 samples" in repr(stream)


def test_bad_blocks_are_named():
    stream = imunoise.AllanStream(FS, channels=3)
    with pytest.raises(imunoise.ImunoiseValueError, match=r"samples must have 3 column"):
        stream.update(np.zeros((10, 2)))
    with pytest.raises(imunoise.ImunoiseValueError, match="finite or NaN .* 1 infinite"):
        stream.update(np.array([[0.0, np.inf, 0.0]]))
    with pytest.raises(imunoise.ImunoiseTypeError, match="real numbers"):
        stream.update(np.array([["a", "b", "c"]]))
    with pytest.raises(imunoise.ImunoiseValueError, match="needs at least 3"):
        stream.result()
    with pytest.raises(imunoise.ImunoiseValueError, match="max_tau must be at least one"):
        imunoise.AllanStream(FS, max_tau=0.001)


def test_missing_samples_are_skipped_as_adev_skips_them():
    """NaN is a gap: every moment the curve and the term counts of
    imunoise.adev(gaps="skip") on the samples so far, per channel."""
    x = imunoise.simulate(30_000, FS, N=1e-3, K=1e-5, channels=2, seed=4) + [9.81, -1.0]
    x[:3, 1] = np.nan  # a channel that starts missing
    x[5000:5400] = np.nan  # a dropout of both
    x[12_345, 0] = np.nan  # one sample of one channel
    x[20_000:20_010, 1] = np.nan
    stream = imunoise.AllanStream(FS, channels=2)
    for a, b in ((0, 4000), (4000, 5200), (5200, 12_346), (12_346, 30_000)):
        stream.update(x[a:b])
        got = stream.result()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", imunoise.GapWarning)
            want = imunoise.adev(x[:b], FS, taus="octave", gaps="skip")
        k = min(len(got.taus), len(want.taus))
        assert k >= len(want.taus) - 1
        np.testing.assert_array_equal(got.m[:k], want.m[:k])
        np.testing.assert_array_equal(got.n[:k], want.n[:k])
        np.testing.assert_allclose(got.dev[:k], want.dev[:k], rtol=1e-10)
    np.testing.assert_array_equal(stream.missing, np.isnan(x).sum(axis=0))
    np.testing.assert_array_equal(got.missing, stream.missing)
    assert np.all(np.isfinite(got.edf)) and np.all(got.ci_low < got.dev)
    # the gaps cost terms: fewer than a record without them
    assert np.all(got.n[0] < len(x) - 1)
