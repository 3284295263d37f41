"""imunoise.dynamic_adev: every window equals imunoise.adev of that window, its EDF is
Greenhall's (checked against allantools), and the stationarity summary finds a
stretch of doubled noise to within one step."""

import warnings

import imunoise
import numpy as np
import pytest
from allantools import ci as at_ci
from imunoise import display
from imunoise._core import allan as core_allan
from imunoise.allan import chi2_interval


def _adev(y, fs, taus):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return imunoise.adev(y, fs, taus=taus)


@pytest.mark.parametrize("channels", [1, 3])
def test_every_window_equals_adev_of_the_window(channels):
    fs = 20.0
    y = imunoise.simulate(30_000, fs, N=1e-2, B=1e-3, K=1e-4, channels=channels, seed=5)
    y = y + 3.0  # an offset the second difference must ignore
    d = imunoise.dynamic_adev(y, fs, window=300.0, step=70.0)
    width = round(d.window * fs)
    assert d.dev.shape[:2] == (len(d.times), len(d.taus))
    for i, start in enumerate(d.starts):
        r = _adev(y[start:start + width], fs, d.taus)
        np.testing.assert_allclose(d.dev[i], r.dev, rtol=1e-10)
        np.testing.assert_array_equal(d.n[i] if channels == 1 else d.n[i, :, 0], r.n)
    np.testing.assert_allclose(d.times, (d.starts + width / 2) / fs)


def test_gaps_are_skipped_like_adev():
    fs = 10.0
    y = imunoise.simulate(20_000, fs, N=1.0, channels=2, seed=1)
    y[3000:3050, 0] = np.nan
    y[9000, 1] = np.nan
    d = imunoise.dynamic_adev(y, fs, window=300.0, step=50.0)
    width = round(d.window * fs)
    for i, start in enumerate(d.starts):
        r = _adev(y[start:start + width], fs, d.taus)
        t = len(r.taus)  # adev drops the taus its gaps leave without two terms
        n = r.n if r.n.ndim == 2 else np.broadcast_to(r.n[:, None], r.dev.shape)
        np.testing.assert_array_equal(d.n[i, :t], n)
        np.testing.assert_allclose(d.dev[i, :t], r.dev, rtol=1e-10)


def test_edf_is_greenhalls_for_the_whole_records_noise_type():
    fs = 10.0
    y = imunoise.simulate(50_000, fs, N=1.0, K=0.01, seed=2)
    d = imunoise.dynamic_adev(y, fs, window=1000.0, step=500.0)
    width = round(d.window * fs)
    for t, m in enumerate(d.m):
        alpha = int(d.whole.alpha[t])
        peer = at_ci.edf_greenhall(alpha=alpha, d=2, m=int(m), N=width + 1, overlapping=True)
        assert d.edf[0, t] == pytest.approx(peer, rel=1e-6)
    # where the window identifies the same noise type, adev of the window agrees
    r = _adev(y[:width], fs, d.taus)
    same = r.alpha == d.whole.alpha
    assert same.any()
    np.testing.assert_allclose(d.edf[0, same], r.edf[same], rtol=1e-12)
    low, high = chi2_interval(d.dev, d.edf, d.confidence)
    np.testing.assert_allclose(d.ci_low, low)
    np.testing.assert_allclose(d.ci_high, high)


def test_estimator_edf_binding_matches_allantools():
    ms = np.array([1, 3, 10, 100], dtype=np.uint64)
    for alpha in (2, 1, 0, -1, -2):
        got = core_allan.estimator_edf("oadev", 5001, np.full(4, alpha, np.int32), ms)
        want = [at_ci.edf_greenhall(alpha=alpha, d=2, m=int(m), N=5001, overlapping=True)
                for m in ms]
        np.testing.assert_allclose(got, want, rtol=1e-6)
    with pytest.raises(ValueError, match="same length"):
        core_allan.estimator_edf("oadev", 100, np.zeros(2, np.int32), ms)


def _doubled_log(seed):
    """5 h at 40 Hz, 3 channels, white + flicker + walk; white noise doubled (std ×2)
    from 2:00:00 to 2:20:00 on every channel."""
    fs = 40.0
    y = imunoise.simulate(int(5 * 3600 * fs), fs, N=1e-3, B=2e-5, K=1e-6, channels=3,
                          seed=seed)
    a, b = int(2 * 3600 * fs), int((2 * 3600 + 20 * 60) * fs)
    extra = np.random.default_rng(seed + 100).normal(size=(b - a, 3))
    y[a:b] += extra * np.sqrt(3) * 1e-3 * np.sqrt(fs)
    return y, fs


@pytest.mark.parametrize("seed", [0, 1])
def test_stationarity_finds_twenty_minutes_of_doubled_noise(seed):
    y, fs = _doubled_log(seed)
    d = imunoise.dynamic_adev(y, fs, window=1800.0, step=300.0)
    summary = d.stationarity
    assert len(summary.intervals) == 3  # one per channel
    for dep in summary.intervals:
        assert abs(dep.start - 7200.0) <= d.step
        assert abs(dep.end - 8400.0) <= d.step
        assert dep.ratio == pytest.approx(2.0, rel=0.1)
        # the ratio's uncertainty from the block's degrees of freedom: the doubled noise
        # is resolved (2 within a few of them) and the text rounds to it ("×2.0", not
        # "×1.98731")
        assert 0.005 < dep.ratio_std < 0.2 * dep.ratio
        assert abs(dep.ratio - 2.0) < 4 * dep.ratio_std
        assert f"×{display.rounded(dep.ratio, dep.ratio_std)}" in repr(summary)
    assert not summary.stationary
    assert np.all(summary.worst_z > 5)
    assert np.all(np.abs(summary.worst_time - 7800.0) <= d.window / 2)


@pytest.mark.parametrize("seed", [3, 4])
def test_stationary_noise_has_no_departure(seed):
    fs = 40.0
    y = imunoise.simulate(int(2 * 3600 * fs), fs, N=1e-3, B=2e-5, K=1e-6, channels=3,
                          seed=seed)
    d = imunoise.dynamic_adev(y, fs, window=900.0, step=150.0)
    summary = d.stationarity
    assert summary.stationary, summary.intervals
    # windows overlap the record, so a little under 1 - confidence lie outside
    assert np.all((summary.outside > 0.1) & (summary.outside < summary.expected_outside + 0.1))


def test_ratio_and_shapes_one_channel():
    y = imunoise.simulate(20_000, 10.0, N=1.0, seed=7)
    d = imunoise.dynamic_adev(y, 10.0)
    assert d.dev.ndim == 2 and d.channels == 1
    np.testing.assert_allclose(d.ratio, d.dev / d.whole.dev[None, :])
    assert d.window == pytest.approx(200.0) and d.step == pytest.approx(33.3, abs=0.1)
    assert d.stationarity.z.shape == d.dev.shape


def test_repr_and_html():
    d = imunoise.dynamic_adev(imunoise.simulate(20_000, 10.0, N=1.0, channels=3, seed=1),
                              10.0, window=300.0, step=100.0)
    for text in (repr(d), repr(d.stationarity)):
        assert len(text.splitlines()) <= 3 and len(text) <= 300
    assert "<table>" in d._repr_html_()


def test_arrays_are_read_only():
    d = imunoise.dynamic_adev(np.random.default_rng(0).normal(size=2000), 1.0, window=500.0)
    with pytest.raises(ValueError):
        d.dev[0, 0] = 1.0


@pytest.mark.parametrize("kwargs, error, message", [
    ({"window": 10_000.0}, ValueError, "window must hold between 3 and 2000"),
    ({"window": 0.0}, ValueError, "window must be positive"),
    ({"window": 100.0, "step": 0.1}, ValueError, "step must be at least one sample"),
    ({"window": "long"}, TypeError, "window must be a real number"),
    ({"window": 100.0, "taus": 0.5}, TypeError, "taus must be"),
    ({"window": 100.0, "taus": "weekly"}, ValueError, "taus must be one of"),
    ({"window": 100.0, "confidence": 2.0}, ValueError, "confidence must be in"),
])
def test_errors_name_the_argument(kwargs, error, message):
    with pytest.raises(error, match=message):
        imunoise.dynamic_adev(np.random.default_rng(0).normal(size=2000), 1.0, **kwargs)


def test_bad_samples():
    with pytest.raises(ValueError, match="finite or NaN"):
        imunoise.dynamic_adev(np.r_[np.ones(100), np.inf], 1.0)
    with pytest.raises(TypeError, match="real numbers"):
        imunoise.dynamic_adev(np.array(["a"] * 100), 1.0)
    with pytest.raises(ValueError, match="fs must be positive"):
        imunoise.dynamic_adev(np.ones(100), 0.0)


def test_plot_heat_map():
    from imunoise import plot

    d = imunoise.dynamic_adev(imunoise.simulate(20_000, 10.0, N=1.0, channels=3, seed=1),
                              10.0, window=300.0, step=100.0)
    fig = d.plot()
    assert len(fig.axes) == 4  # three panels and the colour bar
    with pytest.raises(ValueError, match="limit must be"):
        plot.dynamic(d, limit=1.0)
    with pytest.raises(TypeError, match="DynamicAllan"):
        plot.dynamic(d.whole)


def test_explicit_taus_beyond_the_window_are_dropped_with_a_warning():
    y = np.random.default_rng(0).normal(size=5000)
    with pytest.warns(UserWarning, match="1 of 3 taus dropped"):
        d = imunoise.dynamic_adev(y, 1.0, window=100.0, taus=[1.0, 10.0, 80.0])
    np.testing.assert_array_equal(d.taus, [1.0, 10.0])
    assert d.stationarity is d.stationarity  # computed once


def test_window_count_is_bounded(monkeypatch):
    """A one-sample step over a long record asked for millions of windows at once."""
    from imunoise import dynamic

    monkeypatch.setattr(dynamic, "MAX_WINDOWS", 100)
    y = np.random.default_rng(0).normal(size=2000)
    with pytest.raises(ValueError, match=r"step=1 s gives 1,991 windows; at most 100.*at least "
                                         r"21 s \(21 samples\)"):
        imunoise.dynamic_adev(y, 1.0, window=10.0, step=1.0)
    assert len(imunoise.dynamic_adev(y, 1.0, window=10.0, step=21.0).times) <= 100


def _reference_sums_at(c, bad, mm, points):
    """The whole-array computation the segment-wise one replaced: every τ's squared
    second differences as one array, summed by np.add.reduceat between the points."""
    k = len(c) - 2 * mm
    second = (c[2 * mm:] + c[:k] - 2.0 * c[mm:mm + k]) ** 2
    ok = None if bad is None else (bad[2 * mm:] - bad[:k]) == 0
    if ok is not None:
        second[~ok] = 0.0
    cuts = np.unique(np.r_[0, points[points < k]])
    at = np.searchsorted(np.r_[cuts, k], points)
    sums = np.r_[0.0, np.cumsum(np.add.reduceat(second, cuts))][at]
    if ok is None:
        return sums, points
    return sums, np.r_[0, np.cumsum(np.add.reduceat(ok.astype(np.int64), cuts))][at]


@pytest.mark.parametrize("gaps", [False, True])
def test_segment_wise_second_differences_are_the_whole_arrays_bit_for_bit(gaps):
    from imunoise import dynamic

    rng = np.random.default_rng(5)
    y = rng.standard_normal((50_000, 1)) + np.linspace(0, 3, 50_000)[:, None]
    if gaps:
        y[100:130] = np.nan
        y[31_000] = np.nan
    c, bad = dynamic._phase(y, np.nanmean(y, axis=0), gaps)
    c, bad = c[0], None if bad is None else bad[0]
    for mm in (1, 7, 64, 1000):
        k = len(c) - 2 * mm
        points = np.r_[np.arange(0, k, 4111), rng.integers(0, k + 1, 30), k, 0]
        got = dynamic._second_sums_at(c, bad, mm, points)
        want = _reference_sums_at(c, bad, mm, points)
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])
