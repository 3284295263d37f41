"""describe / distribution against numpy and scipy directly; quantization step detection."""

import warnings

import imunoise
import numpy as np
import pytest
from imunoise import stats
from imunoise.stats import quantization_step
from scipy import stats as sstats


def _log(n=4000, fs=40.0, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    gyro = rng.normal(0, 1e-3, (n, 3)) + np.array([1e-4, -2e-4, 3e-4])
    accel = rng.normal(0, 0.01, (n, 3)) + np.array([0.0, 0.0, -9.81])
    accel[:, 0] += 0.5 * t / 3600.0  # 0.5 m/s^2 per hour drift on X
    return imunoise.ImuLog.from_arrays(fs, gyro=gyro, accel=accel), gyro, accel


def test_describe_log_matches_numpy():
    log, gyro, accel = _log()
    d = imunoise.describe(log)
    x = np.hstack([gyro, accel])
    assert d.names == ("gyro X", "gyro Y", "gyro Z", "accel X", "accel Y", "accel Z")
    assert d.units == ("rad/s",) * 3 + ("m/s^2",) * 3
    np.testing.assert_allclose(d.mean, x.mean(axis=0), rtol=1e-12)
    np.testing.assert_allclose(d.std, x.std(axis=0, ddof=1), rtol=1e-12)
    np.testing.assert_allclose(d.var, x.var(axis=0, ddof=1), rtol=1e-12)
    np.testing.assert_array_equal(d.min, x.min(axis=0))
    np.testing.assert_array_equal(d.max, x.max(axis=0))
    t = np.arange(len(x)) / log.fs
    slopes = [np.polyfit(t, x[:, j], 1)[0] * 3600 for j in range(6)]
    np.testing.assert_allclose(d.drift_per_hour, slopes, rtol=1e-8, atol=1e-12)
    assert abs(d.drift_per_hour[3] - 0.5) < 0.1


def test_describe_array_and_table():
    x = np.arange(10.0)
    d = imunoise.describe(x, fs=2.0)
    assert d.names == ("x",)
    np.testing.assert_allclose(d.drift_per_hour, [2.0 * 3600])
    assert np.isnan(imunoise.describe(x).drift_per_hour[0])
    text = d.table()
    assert "drift/h" in text and "7200" in text
    with pytest.raises(ValueError, match="fs"):
        imunoise.describe(x, fs=-1)
    assert list(imunoise.describe([1.0, np.nan, 2.0]).missing) == [1]
    with pytest.raises(ValueError, match="finite"):
        imunoise.describe([1.0, np.inf, 2.0])
    with pytest.raises(TypeError, match="dtype"):
        imunoise.describe(np.array(["a", "b"]))
    with pytest.warns(DeprecationWarning, match=r"describe\(log_or_array=...\)"):
        old = imunoise.describe(log_or_array=x, fs=2.0)
    np.testing.assert_array_equal(old.drift_per_hour, d.drift_per_hour)


def test_distribution_bins_by_position_is_deprecated():
    x = np.random.default_rng(1).normal(size=500)
    with pytest.warns(DeprecationWarning, match="bins= by keyword"):
        old = imunoise.distribution(x, 15)
    np.testing.assert_array_equal(old.edges, imunoise.distribution(x, bins=15).edges)


def test_distribution_matches_scipy():
    rng = np.random.default_rng(3)
    x = rng.standard_t(8, size=5000) * 0.2 + 1.0
    d = imunoise.distribution(x)
    mu, sigma = sstats.norm.fit(x)
    assert d.mu == pytest.approx(mu, rel=1e-12) and d.sigma == pytest.approx(sigma, rel=1e-12)
    ks = sstats.kstest(x, "norm", args=(mu, sigma))
    assert d.ks_statistic == pytest.approx(ks.statistic, rel=1e-12)
    assert d.ks_pvalue == pytest.approx(ks.pvalue, rel=1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        ad = sstats.anderson(x, "norm").statistic
    assert d.ad_statistic == pytest.approx(ad, rel=1e-12)
    assert d.skewness == pytest.approx(sstats.skew(x), rel=1e-12)
    assert d.excess_kurtosis == pytest.approx(sstats.kurtosis(x), rel=1e-12)
    assert d.excess_kurtosis > 0.3  # t(8) has excess kurtosis 1.5
    assert d.step is None
    assert d.counts.sum() == len(x)
    np.testing.assert_array_equal(d.counts, np.histogram(x, d.edges)[0])
    np.testing.assert_allclose(d.edges, np.histogram_bin_edges(x, bins=len(d.counts)))
    np.testing.assert_allclose(np.sum(d.density() * np.diff(d.edges)), 1.0)
    assert np.all(np.diff(d.qq_sample) >= 0)
    np.testing.assert_allclose(d.qq_sample, np.quantile(x, sstats.norm.cdf(d.qq_theoretical)))


def test_distribution_in_chunks_is_the_whole_sample(monkeypatch):
    """Chunks of the sorted samples (a prime count, so the mirror chunks of A² are
    cut elsewhere than the chunks) give scipy's statistics and the same step."""
    rng = np.random.default_rng(3)
    x = rng.standard_t(8, size=20_000) * 0.2 + 1.0
    quantized = np.round(x, 3)
    whole = imunoise.distribution(quantized)
    monkeypatch.setattr(stats, "CHUNK", 997)
    d = imunoise.distribution(x)
    assert d.ks_statistic == pytest.approx(
        sstats.kstest(x, "norm", args=sstats.norm.fit(x)).statistic, rel=1e-12)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FutureWarning)
        assert d.ad_statistic == pytest.approx(sstats.anderson(x, "norm").statistic, rel=1e-9)
    assert d.skewness == pytest.approx(sstats.skew(x), rel=1e-12)
    assert d.excess_kurtosis == pytest.approx(sstats.kurtosis(x), rel=1e-12)
    assert d.step is None
    q = imunoise.distribution(quantized)
    assert q.step == whole.step == pytest.approx(1e-3)
    np.testing.assert_array_equal(q.counts, whole.counts)


@pytest.mark.parametrize("step", [1e-3, 0.5, 2.0**-12, 1e-6])
def test_quantization_step_detected(step):
    rng = np.random.default_rng(7)
    levels = np.round(rng.normal(0, 7 * step, 3000) / step)
    # Values as a logger prints them: text with a fixed number of decimals.
    decimals = max(0, int(np.ceil(-np.log10(step))) + 4)
    x = np.array([float(f"{v:.{decimals}f}") for v in levels * step + 13 * step])
    q = quantization_step(x)
    assert q == pytest.approx(step, rel=1e-6)


def test_quantization_gcd_not_min_difference():
    # Levels only at even and odd multiples 2q, 3q apart: the step is q, not 2q.
    x = np.array([0.0, 0.2, 0.5, 0.7, 1.0]) * 1.0
    assert quantization_step(x) == pytest.approx(0.1, rel=1e-9)


def test_continuous_and_constant_have_no_step():
    rng = np.random.default_rng(0)
    assert quantization_step(rng.normal(size=10000)) is None
    assert quantization_step(np.full(10, 3.0)) is None


def test_quantized_bins_hold_each_level_once():
    rng = np.random.default_rng(5)
    step = 0.001
    x = np.round(rng.normal(0.02, 0.004, 20000) / step) * step
    d = imunoise.distribution(x)
    assert d.step == pytest.approx(step, rel=1e-6)
    widths = np.diff(d.edges)
    k = np.round(widths / step)
    np.testing.assert_allclose(widths, k * step, rtol=1e-9)
    # Every level sits strictly inside a bin, half a step from the nearest edge or more.
    levels = np.unique(x)
    pos = (levels - d.edges[0]) / step
    np.testing.assert_allclose(pos - 0.5, np.round(pos - 0.5), atol=1e-6)
    assert d.counts.sum() == len(x)
    np.testing.assert_array_equal(d.counts, np.histogram(x, d.edges)[0])
    # Each bin holds the same number of levels: counts of a 1-step histogram summed by k.
    one = imunoise.distribution(x, bins=np.arange(x.min() - step / 2, x.max() + step, step))
    kk = int(k[0])
    pad = (-len(one.counts)) % kk
    grouped = np.add.reduceat(np.concatenate([one.counts, np.zeros(pad, int)]),
                              np.arange(0, len(one.counts) + pad, kk))
    np.testing.assert_array_equal(grouped[: len(d.counts)], d.counts)


def test_large_sample_ks_is_asymptotic():
    x = np.random.default_rng(4).normal(size=50_000) + 0.002 * np.arange(50_000) ** 0.5
    d = imunoise.distribution(x)
    ks = sstats.kstest(x, "norm", args=sstats.norm.fit(x), method="asymp")
    assert d.ks_statistic == pytest.approx(ks.statistic, rel=1e-12)
    assert d.ks_pvalue == pytest.approx(ks.pvalue, rel=1e-9, abs=1e-300)


def test_distribution_int_bins_and_errors():
    x = np.round(np.random.default_rng(1).normal(0, 10, 1000))
    d = imunoise.distribution(x, bins=15)
    assert d.step == pytest.approx(1.0)
    assert 10 <= len(d.counts) <= 16
    with pytest.raises(ValueError, match="1-D"):
        imunoise.distribution(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="bins"):
        imunoise.distribution(x, bins=0)
    with pytest.raises(ValueError, match="bins"):
        imunoise.distribution(x, bins="nonsense")
    with pytest.raises(ValueError, match="finite"):
        imunoise.distribution([1.0, 2.0, np.inf])


def test_sparse_levels_use_the_level_spacing():
    # A magnetometer-like LSB of 0.92e-3 printed with four decimals: values on the 1e-4
    # grid, but only every ninth or tenth grid point occupied.
    rng = np.random.default_rng(9)
    lsb = 0.92e-3
    x = np.round(np.round(rng.normal(0.0466, 0.0013, 13000) / lsb) * lsb, 4)
    d = imunoise.distribution(x)
    assert d.step == pytest.approx(1e-4, rel=1e-6)
    assert d.level_spacing == pytest.approx(lsb, rel=0.02)
    # every sensor level in its own bin, no empty bins between occupied ones
    levels = np.unique(x)
    which = np.searchsorted(d.edges, levels, side="right") - 1
    assert len(np.unique(which)) == len(levels)
    inner = d.counts[np.flatnonzero(d.counts)[0]: np.flatnonzero(d.counts)[-1] + 1]
    assert np.count_nonzero(inner == 0) <= 0.05 * len(inner)


def test_real_vn100_magnetometer_has_no_comb():
    from importlib import resources

    text = (resources.files("imunoise") / "data" / "vn100_stationary_5min.txt").read_text()
    mag = np.array([[float(v) for v in line.split(",")[4:7]] for line in text.splitlines()])
    for j in range(3):
        d = imunoise.distribution(mag[:, j])
        assert d.step == pytest.approx(1e-4, rel=1e-6)
        assert 6e-4 < d.level_spacing < 1.3e-3
        nz = np.flatnonzero(d.counts)
        inner = d.counts[nz[0]: nz[-1] + 1]
        # the 1e-4 grid would leave most bins empty; level-spacing bins leave almost none
        assert np.count_nonzero(inner == 0) <= 0.1 * len(inner)
        assert d.counts.sum() == len(mag)
