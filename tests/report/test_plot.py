"""Figures render headless, decimation keeps every extreme, PNG and SVG are written."""

import time

import imunoise
import numpy as np
import pytest
from imunoise import plot


def test_decimate_minmax_keeps_extremes():
    rng = np.random.default_rng(0)
    y = rng.normal(size=1_000_003)
    y[123_457] = 50.0  # one spike
    y[900_001] = -40.0
    start, lo, hi = plot.decimate_minmax(y, 997)
    assert len(start) == len(lo) == len(hi) == 997
    assert hi.max() == 50.0 and lo.min() == -40.0
    for b in (0, 500, 996):
        end = start[b + 1] if b + 1 < len(start) else len(y)
        assert lo[b] == y[start[b]:end].min() and hi[b] == y[start[b]:end].max()
    s, lo2, hi2 = plot.decimate_minmax(y[:10], 100)
    np.testing.assert_array_equal(lo2, y[:10])
    with pytest.raises(ValueError, match="columns"):
        plot.decimate_minmax(y, 0)


def test_time_series_ten_million_points_is_fast(tmp_path):
    y = np.random.default_rng(1).normal(size=(10_000_000, 1)).astype(np.float32)
    t0 = time.perf_counter()
    fig = plot.time_series(y, 40.0, title="big", unit="rad/s")
    paths = plot.save(fig, tmp_path / "big", formats=("png",))
    assert time.perf_counter() - t0 < 10.0
    assert paths[0].read_bytes()[:4] == b"\x89PNG"


def test_histograms_and_allan_render(tmp_path):
    rng = np.random.default_rng(2)
    x = np.round(rng.normal(0, 1e-3, (20000, 3)), 5)
    dists = [imunoise.distribution(x[:, j]) for j in range(3)]
    fig = plot.histograms(dists, title="gyro", unit="rad/s")
    png, svg = plot.save(fig, tmp_path / "hist")
    assert png.stat().st_size > 5000 and b"<svg" in svg.read_bytes()[:2000]
    r = imunoise.adev(x, 40.0)
    coeffs = [{"Q": 0.0, "N": 1e-3 / np.sqrt(40.0), "B": 1e-5, "K": 1e-6, "R": 0.0}] * 3
    fig = plot.allan(r, coefficients=coeffs, title="gyro ADEV", unit="rad/s")
    axes = fig.get_axes()
    assert len(axes) == 3
    labels = [line.get_label() for line in axes[0].get_lines()]
    assert "model" in labels and "N at τ=1 s" in labels and "K at τ=3 s" in labels
    n_point = [ln for ln in axes[0].get_lines() if ln.get_label() == "N at τ=1 s"][0]
    assert tuple(n_point.get_xydata()[0]) == pytest.approx((1.0, coeffs[0]["N"]))
    plot.save(fig, tmp_path / "adev")
    assert (tmp_path / "adev.png").is_file() and (tmp_path / "adev.svg").is_file()


def test_coefficient_curves_follow_ieee952():
    rng = np.random.default_rng(3)
    r = imunoise.adev(rng.normal(0, 1e-3, (20000, 1)), 40.0)
    c = {"Q": 1e-4, "N": 2e-3, "B": 5e-4, "K": 1e-5, "R": 1e-7}
    fig = plot.allan(r, coefficients=[c])
    lines = {ln.get_label(): ln.get_xydata() for ln in fig.get_axes()[0].get_lines()}
    tau, n = lines["white noise N"].T
    np.testing.assert_allclose(n * np.sqrt(tau), c["N"])  # N read off at tau = 1 s
    tau, k = lines["rate random walk K"].T
    np.testing.assert_allclose(k / np.sqrt(tau / 3), c["K"])  # K read off at tau = 3 s
    np.testing.assert_allclose(lines["bias instability B"][:, 1],
                               c["B"] * np.sqrt(2 * np.log(2) / np.pi))
    labels = ("quantization Q", "white noise N", "bias instability B", "rate random walk K",
              "rate ramp R")
    total2 = sum(lines[label][:, 1] ** 2 for label in labels)
    np.testing.assert_allclose(lines["model"][:, 1] ** 2, total2)


def test_missing_samples_leave_a_hole_and_are_shaded():
    y = np.random.default_rng(2).normal(size=100_000)
    y[40_000:60_000] = np.nan
    y[10] = np.nan  # a single missing sample does not blank its bucket
    start, lo, hi = plot.decimate_minmax(y, 100)
    assert np.isfinite(lo[0]) and np.isfinite(hi[0])
    assert np.isnan(lo[45]) and np.isnan(hi[45])
    fig = plot.time_series(y, 100.0, gaps=[(400.0, 200.0)])
    ax = fig.axes[0]
    shaded = [p for p in ax.patches if p.get_facecolor()[:3] == pytest.approx(
        tuple(int(plot.GAP_COLOR[i:i + 2], 16) / 255 for i in (1, 3, 5)))]
    assert len(shaded) == 1


def test_b_marker_sits_where_model_b_is_read_and_the_data_floor_is_marked():
    # N + B only: the model keeps falling past the fitted taus (the plot's grid runs
    # beyond them), so its minimum over the plot grid lies outside the data.
    x = imunoise.simulate(400_000, 40.0, N=1e-3, B=2e-4, seed=2)
    r = imunoise.adev(x, 40.0, taus=10)
    m = imunoise.fit(r, terms=["N", "B"], warn_coverage=False)
    fig = plot.allan(r, model=m)
    lines = {ln.get_label(): ln for ln in fig.axes[0].get_lines()}
    tau_b = float(lines["B·0.664 floor"].get_xdata()[0])
    assert m.taus[0] <= tau_b <= m.taus[-1]
    assert float(lines["B·0.664 floor"].get_ydata()[0]) == pytest.approx(
        float(m.B) * imunoise.noise.FLICKER)
    tau_read = float(lines["data's floor (read-off B)"].get_xdata()[0])
    assert tau_read == pytest.approx(float(m.readoff["B"]["tau"]))


def test_tone_is_drawn_as_its_envelope_not_a_comb():
    x = imunoise.simulate(200_000, 40.0, N=1e-4, channels=1, seed=3, sinusoid=(5e-4, 7.3))
    r = imunoise.adev(x, 40.0, taus=20)
    m = imunoise.fit(r, terms=["N", "sine"], warn_coverage=False)
    assert m.components.sine(0)
    fig = plot.allan(r, model=m)
    line = next(ln for ln in fig.axes[0].get_lines() if ln.get_label() == "tone (envelope)")
    y = np.asarray(line.get_ydata(), dtype=float)
    assert np.all(np.isfinite(y) & (y > 0))  # no masked zeros at whole periods
    after = y[int(np.argmax(y)):]
    assert np.all(np.diff(after) <= 1e-12 * after[:-1])  # falls monotonically past the peak
