"""The streamed report's memory-lean pieces give the numbers of the plain ones: the
Allan deviation a column at a time, the distribution sorting its input in place and
reading its quantiles from the sort, Welch pieces of a record whose segment alone
exceeds a piece, the attitude plot from columns."""

import warnings

import numpy as np
import pytest
import scipy.signal
from imunoise import allan, plot, spectrum, stats


def fields_equal(a, b) -> None:
    for name in a.__dataclass_fields__:
        x, y = getattr(a, name), getattr(b, name)
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and x.shape == y.shape, name
            np.testing.assert_array_equal(x, y, err_msg=name)
        else:
            assert x == y or (x != x and y != y), name


@pytest.mark.parametrize("gaps", [False, True])
def test_adev_a_column_at_a_time_is_adev_of_the_stacked_samples(gaps):
    rng = np.random.default_rng(1)
    x = rng.standard_normal((60_000, 3)).cumsum(axis=0) * 1e-3 + rng.standard_normal((60_000, 3))
    if gaps:
        x[1000:1400, 1] = np.nan
        x[:5, 2] = np.nan
    for taus in ("octave", 10):
        fields_equal(allan.adev_by_column(lambda j: x[:, j].copy(), 3, 50.0, taus=taus),
                     allan.adev(x, 50.0, taus=taus))


def test_adev_by_column_falls_back_when_the_columns_keep_different_taus():
    rng = np.random.default_rng(2)
    x = rng.standard_normal((4_000, 2))
    x[::50, 1] = np.nan  # channel 1 has no run long enough for the longest taus
    stacked = allan.adev(x, 10.0, taus=[0.1, 1.0, 40.0])  # channel 1 NaN at 40 s
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # channel 1's own call dropped 40 s: not said
        by_column = allan.adev_by_column(lambda j: x[:, j].copy(), 2, 10.0,
                                         taus=[0.1, 1.0, 40.0])
    assert len(by_column.taus) == 3 and np.isnan(by_column.dev[-1, 1])
    fields_equal(by_column, stacked)


def test_distribution_sorting_in_place_gives_the_same_numbers():
    rng = np.random.default_rng(3)
    x = np.round(rng.standard_normal(200_001) * 3, 2)  # quantized: levels, snapped bins
    kept = x.copy()
    plain = stats.distribution(x)
    np.testing.assert_array_equal(x, kept)  # the default leaves x alone
    own = stats.distribution(kept, overwrite_input=True)
    assert np.all(np.diff(kept) >= 0)  # sorted in place: no copy was made
    fields_equal(own, plain)
    with pytest.raises(TypeError, match="overwrite_input"):
        stats.distribution(x, overwrite_input=1)


def test_quantiles_of_sorted_samples_are_numpys():
    rng = np.random.default_rng(4)
    q = [0.0, 0.005, 0.25, 0.5, 0.995, 1.0]
    for n in (1, 2, 3, 10, 199, 200_003):
        xs = np.sort(rng.standard_normal(n))
        np.testing.assert_array_equal(stats.sorted_quantiles(xs, q), np.quantile(xs, q))


def test_welch_pieces_of_segments_larger_than_a_piece(monkeypatch):
    """A record whose one segment exceeds WELCH_PIECE (a 24 h, 800 Hz log's 2²³-sample
    segments): every segment is averaged once (a piece per segment, none empty)."""
    rng = np.random.default_rng(5)
    x = rng.standard_normal((1 << 14, 3))
    whole = spectrum.psd(x, 100.0)
    monkeypatch.setattr(spectrum, "WELCH_PIECE", 1 << 10)
    pieces = spectrum.psd(x, 100.0)
    f, p = scipy.signal.welch(x, fs=100.0, window="hann", nperseg=1 << 11, noverlap=1 << 10,
                              detrend="constant", scaling="density", axis=0)
    np.testing.assert_allclose(pieces.psd, whole.psd, rtol=1e-12)
    np.testing.assert_allclose(np.asarray(pieces.psd).reshape(len(pieces.f), -1),
                               p[1:], rtol=1e-12)


def test_time_series_of_columns_is_that_of_the_stacked_array():
    rng = np.random.default_rng(6)
    cols = [rng.standard_normal(5_000) for _ in range(3)]
    a = plot.time_series(cols, 10.0, names=["yaw", "pitch", "roll"])
    b = plot.time_series(np.column_stack(cols), 10.0, names=["yaw", "pitch", "roll"])
    for ax_a, ax_b in zip(a.axes, b.axes, strict=True):
        for la, lb in zip(ax_a.get_lines(), ax_b.get_lines(), strict=True):
            np.testing.assert_array_equal(la.get_xydata(), lb.get_xydata())
    with pytest.raises(ValueError, match="one length"):
        plot.time_series([cols[0], cols[1][:10]], 10.0)
