"""imunoise.psd: the one-sided convention, its bands, the N read-off and the power laws,
checked against scipy, SP 1065's integral, allantools, imunoise.fit and real logs."""

import math
import warnings

import imunoise
import numpy as np
import pytest
from allantools import psd2allan
from helpers.data import shared_file
from imunoise import spectrum
from imunoise.cli import bundled_log
from imunoise.noise import model_variance
from scipy import integrate, signal

FS = 100.0


def test_matches_scipy_welch_and_parseval():
    y = imunoise.simulate(2**16, FS, N=0.01, B=1e-3, seed=4)
    s = imunoise.psd(y, FS, nperseg=4096)
    f, p = signal.welch(y, fs=FS, nperseg=4096, noverlap=2048, window="hann")
    np.testing.assert_allclose(s.f, f[1:])
    np.testing.assert_allclose(s.psd, p[1:], rtol=1e-12)
    # one-sided: the density integrates to the variance of the (mean-removed) samples
    assert np.sum(s.psd) * (s.f[1] - s.f[0]) == pytest.approx(np.var(y), rel=0.05)
    assert s.asd == pytest.approx(np.sqrt(s.psd))


def test_white_level_is_twice_n_squared():
    # simulate draws white samples of std N·√fs (two-sided density N²); the one-sided
    # level must be 2N², and N = √(level/2) must give back N and agree with the ADEV fit
    n_true = 2e-3
    y = imunoise.simulate(400_000, FS, N=n_true, seed=11)
    s = imunoise.psd(y, FS)
    assert np.median(s.psd) == pytest.approx(2 * n_true**2, rel=0.02)
    assert abs(s.N - n_true) < 4 * s.N_std
    model = imunoise.fit(imunoise.adev(y, FS), terms=["N"])
    assert abs(s.N - model.N) < 2 * math.hypot(s.N_std, model.N_std)
    # the datasheet unit of docs/noise.md: N in rad/s/√Hz converts like rad/√s
    assert imunoise.units.convert(s.N, "N", "deg/s/sqrt(Hz)") == pytest.approx(
        np.degrees(s.N))


def test_n_agrees_with_adev_fit_on_40_records():
    # white + rate random walk + flicker: each N within the combined uncertainty
    scores = []
    for seed in range(40):
        y = imunoise.simulate(2**17, FS, N=1e-3, B=1e-4, K=2e-5, seed=seed)
        s = imunoise.psd(y, FS)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = imunoise.fit(imunoise.adev(y, FS))
        scores.append((s.N - model.N) / math.hypot(s.N_std, model.N_std))
    scores = np.array(scores)
    assert np.mean(np.abs(scores) < 2) >= 0.9, scores
    assert np.mean(scores**2) < 2.0, scores
    assert abs(np.mean(scores)) < 0.5, scores


def test_confidence_band_covers_the_true_level():
    y = imunoise.simulate(2**17, FS, N=1e-3, seed=3)
    s = imunoise.psd(y, FS, confidence=0.9)
    inside = (s.ci_low <= 2e-6) & (2e-6 <= s.ci_high)
    assert 0.85 < inside.mean() < 0.95
    smooth = s.smooth(10)
    assert np.all(smooth.edf >= s.edf[0] * 0.99) and smooth.edf[-2] > 100 * s.edf[0]
    inside = (smooth.ci_low <= 2e-6) & (2e-6 <= smooth.ci_high)
    assert inside.mean() > 0.75


def test_gaps_leave_out_the_segments_that_hold_them():
    y = imunoise.simulate(2**17, FS, N=1e-3, B=1e-4, channels=2, seed=8)
    gapped = y.copy()
    gapped[30_000:30_050] = np.nan  # a gap in both channels
    gapped[90_000, 1] = np.nan  # one channel: the row counts as missing for both
    s = imunoise.psd(gapped, FS, nperseg=4096)
    step = 2048
    starts = [a for a in range(0, len(y) - 4096 + 1, step)
              if np.isfinite(gapped[a:a + 4096]).all()]
    assert s.segments == len(starts) and s.segments_skipped == 63 - len(starts) == 4
    # the oracle: scipy's periodogram of each gap-free segment, averaged
    p = np.mean([signal.welch(y[a:a + 4096], fs=FS, nperseg=4096, window="hann",
                              axis=0)[1] for a in starts], axis=0)
    np.testing.assert_allclose(s.psd, p[1:], rtol=1e-12)
    whole = imunoise.psd(y, FS, nperseg=4096)
    assert s.edf[0] < whole.edf[0] and np.all(abs(s.N - whole.N) < 3 * whole.N_std)
    assert "4 of 63 segments left out" in repr(s)


def test_default_segments_fit_between_many_gaps():
    # an outlier every 3000 samples excluded (as MTi-G's 217 events): the default
    # segment of an unbroken record (n/8) would keep none; the default keeps half the
    # samples and the longest such segment
    y = imunoise.simulate(2**18, FS, N=1e-3, seed=2)
    y[np.arange(1_500, len(y), 3_000)] = np.nan
    s = imunoise.psd(y, FS)
    kept = s.segments * s.nperseg // 2
    assert kept >= 0.5 * np.count_nonzero(np.isfinite(y))
    longer = imunoise.psd(y, FS, nperseg=2 * s.nperseg)
    assert longer.segments * s.nperseg < 0.5 * np.count_nonzero(np.isfinite(y))
    assert abs(s.N - 1e-3) < 3 * s.N_std


def test_welch_edf_counts_only_the_overlaps_that_remain():
    # P&W 292b for an unbroken record; segments with no neighbour are independent: 2K
    w = signal.get_window("hann", 64)
    rho = np.sum(w[:-32] * w[32:]) / np.sum(w * w)
    unbroken = spectrum._welch_edf(64, np.arange(10) * 32)
    assert unbroken == pytest.approx(20 / (1 + 2 * 0.9 * rho**2))
    assert spectrum._welch_edf(64, np.arange(10) * 96) == pytest.approx(20.0)


def test_gapped_spectrum_scatter_matches_its_edf():
    # the values' scatter about the true level is what the EDF says: var(S/h0) = 2/ν
    y = imunoise.simulate(2**18, FS, N=1e-3, seed=9)
    y[np.arange(300, len(y), 2_000)] = np.nan  # a missing sample every 2000: a quarter of
    # the segments are left out, and the overlaps of their neighbours with them
    s = imunoise.psd(y, FS, nperseg=512)
    ratio = s.psd[5:-5] / 2e-6
    assert s.segments_skipped > 0.15 * (s.segments + s.segments_skipped)
    assert np.var(ratio) == pytest.approx(2 / s.edf[5], rel=0.1)


def test_events_excluded_as_missing_keep_n():
    # a record with bursts: their excluded samples leave the white level as it was
    fs = 40.0
    rng = np.random.default_rng(5)
    y = 1e-3 * rng.standard_normal(200_000)
    clean = imunoise.psd(y, fs)
    for start in range(10_000, 190_000, 20_000):
        y[start:start + 80] += 1e-2 * rng.standard_normal(80)
    found = imunoise.events(y, fs)
    assert len(found) == 9
    loud = imunoise.psd(y, fs)
    quiet = imunoise.psd(found.exclude(y), fs)
    assert loud.N > 1.05 * clean.N
    assert abs(quiet.N - clean.N) < 3 * clean.N_std and quiet.segments_skipped >= 9


@pytest.mark.parametrize("term", ["N", "B", "K"])
def test_power_laws_match_sp1065_integral(term):
    # σ²(τ) = 2∫ S_y(f) sin⁴(πfτ)/(πfτ)² df (SP 1065 eq. 65) of each term's one-sided PSD
    tau, c = 2.0, 0.3
    law = spectrum.POWER_LAWS[term]

    def integrand(f):
        return 2 * spectrum.term_psd(term, c, f) * np.sin(np.pi * f * tau) ** 4 / (
            np.pi * f * tau) ** 2

    value = sum(integrate.quad(integrand, a, b, limit=400)[0]
                for a, b in ((1e-9, 1e-3), (1e-3, 1.0), (1.0, 200.0)))
    expected = law.avar_factor * c**2 * tau**law.mu
    assert value == pytest.approx(expected, rel=2e-3)
    assert model_variance(np.array([tau]), **{term: c})[0] == pytest.approx(expected, rel=1e-12)


def test_white_law_matches_allantools_psd2allan():
    h0 = 2 * 0.01**2
    f = np.linspace(0, 50.0, 5001)
    taus, ad = psd2allan(np.full(f.size, h0), f)
    n = spectrum.coefficient_from_psd("N", h0, 1.0)
    keep = (taus > 0.05) & (taus < 5)
    np.testing.assert_allclose(ad[keep], n / np.sqrt(taus[keep]), rtol=0.02)


def test_quantization_law_matches_simulation():
    y = imunoise.simulate(2**17, FS, Q=1e-3, seed=8)
    s = imunoise.psd(y, FS).smooth(10)
    expected = spectrum.term_psd("Q", 1e-3, s.f, fs=FS)
    assert np.median(s.psd / expected) == pytest.approx(1.0, rel=0.03)
    assert spectrum.coefficient_from_psd("Q", expected, s.f, fs=FS) == pytest.approx(1e-3)


def test_model_overlay_follows_the_spectrum():
    y = imunoise.simulate(2**18, FS, N=1e-3, K=1e-4, B=2e-4, seed=2)
    model = imunoise.fit(imunoise.adev(y, FS))
    s = imunoise.psd(y, FS).smooth(10)
    ratio = s.psd / spectrum.model_psd(model, s.f)
    assert np.median(np.abs(np.log(ratio))) < 0.1


def test_band_stops_below_a_low_pass_filter():
    # white noise through a 4th-order low-pass at 20 Hz: the top bends down, and the
    # automatic band must end below the bend with the unfiltered level
    rng = np.random.default_rng(5)
    white = rng.normal(size=2**18) * 1e-3 * math.sqrt(FS)
    b, a = signal.butter(4, 20.0, fs=FS)
    s = imunoise.psd(signal.lfilter(b, a, white), FS)
    assert s.band[1] < 20.0
    assert s.N == pytest.approx(1e-3, rel=0.02)


def test_spectral_line_is_left_out_not_a_band_edge():
    # white noise plus a 7 Hz sinusoid of 20× the white variance per bin: N unchanged,
    # the band still reaches the top, and the line is reported
    rng = np.random.default_rng(12)
    n = 2**18
    t = np.arange(n) / FS
    y = rng.normal(size=n) * 1e-3 * math.sqrt(FS) + 0.02 * np.sin(2 * np.pi * 7.0 * t)
    s = imunoise.psd(y, FS)
    assert s.N == pytest.approx(1e-3, rel=0.01)
    assert s.band[1] > 40.0
    assert np.any(np.abs(s.lines[0] - 7.0) < 0.5), s.lines
    assert imunoise.psd(y, FS, band=(1.0, 5.0)).lines[0].size == 0


def test_band_stops_below_quantization_noise():
    y = imunoise.simulate(2**18, FS, N=1e-3, Q=1e-4, seed=6)
    s = imunoise.psd(y, FS)
    assert s.band[1] < FS / 2 * 0.9
    assert abs(s.N - 1e-3) < max(4 * s.N_std, 0.02e-3)


def test_user_band_and_channels():
    y = imunoise.simulate(2**16, FS, N=1e-3, channels=3, seed=9)
    s = imunoise.psd(y, FS, band=(1.0, 10.0))
    assert s.psd.shape == (len(s.f), 3) and s.N.shape == (3,)
    np.testing.assert_allclose(s.band, [[1.0, 10.0]] * 3)
    assert not s.band_auto and np.all(s.flicker == 0)
    np.testing.assert_allclose(s.N, 1e-3, rtol=0.05)
    one = imunoise.psd(y[:, 1], FS, band=(1.0, 10.0))
    assert one.N == pytest.approx(s.N[1])


def test_repr_and_html():
    s = imunoise.psd(imunoise.simulate(4096, FS, N=1.0, channels=3, seed=1), FS)
    text = repr(s)
    assert len(text.splitlines()) <= 3 and len(text) <= 300
    assert "Spectrum" in text and "<table>" in s._repr_html_()


@pytest.mark.parametrize("kwargs, message", [
    ({"x": [1.0] * 8}, "at least 16"),
    ({"x": np.r_[np.ones(100), np.inf]}, "finite or NaN"),
    ({"x": np.where(np.arange(200) % 10 == 0, np.nan, 1.0)}, "no stretch of 16 samples"),
    ({"x": np.r_[np.ones(600), np.nan, np.ones(600)], "nperseg": 1024},
     r"no stretch of nperseg = 1024 .*\(the longest is 600\); pass nperseg <= 600"),
    ({"fs": -1.0}, "fs must be positive"),
    ({"nperseg": 10**6}, "nperseg must be <="),
    ({"nperseg": 4}, "nperseg must be >= 16"),
    ({"band": (10.0, 1.0)}, "band must satisfy"),
    ({"band": (1.0, 80.0)}, "fs/2"),
    ({"confidence": 1.5}, "confidence must be in"),
])
def test_errors_name_the_argument(kwargs, message):
    args = {"x": np.random.default_rng(0).normal(size=1000), "fs": FS, **kwargs}
    with pytest.raises(ValueError, match=message):
        imunoise.psd(args.pop("x"), args.pop("fs"), **args)


def test_type_errors():
    with pytest.raises(TypeError, match="band must be a pair"):
        imunoise.psd(np.ones(100), FS, band=3.0)
    with pytest.raises(TypeError, match="nperseg must be an integer"):
        imunoise.psd(np.ones(100), FS, nperseg=32.0)
    with pytest.raises(ValueError, match="term must be one of"):
        spectrum.term_psd("X", 1.0, 1.0)
    with pytest.raises(ValueError, match="fs is required"):
        spectrum.term_psd("Q", 1.0, 1.0)


def _adis_gyro():
    d = np.load(shared_file("data/other-imu/adis16405_static_2h47m.npz"))
    return d["gyro_counts"] * float(d["gyro_scale_dps_per_count"]), float(d["sample_rate_hz"])


def test_real_adis16405_n_agrees_with_adev_where_no_line():
    # X and Y: PSD and ADEV-fit N (the model's N read-off) within 5 %. Z carries a
    # spectral line near 20 Hz, above the white band, that the ADEV's short taus add
    # to N: the disagreement is explained by the spectrum itself.
    g, fs = _adis_gyro()
    s = imunoise.psd(g, fs)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = imunoise.fit(imunoise.adev(g, fs))
    ratio = s.N / model.value("N")
    assert np.all(np.abs(ratio[:2] - 1) < 0.05), ratio
    assert np.all(s.band[:, 1] < 20.0)  # the gyro filter bends the top: excluded
    above = s.f > s.band[2, 1]
    assert s.psd[above, 2].max() > 3 * s.white[2] or np.any(s.lines[2] > 15)


def test_real_vn100_bundled_log():
    log = imunoise.read(bundled_log(), fs=40.0)
    s = imunoise.psd(log.gyro, log.fs)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = imunoise.fit(imunoise.adev(log.gyro, log.fs))
    ratio = s.N / model.value("N")
    # Y: a line at 17–19 Hz; the PSD read-off finds it and leaves it out, and the ADEV
    # model takes it as its tone term, so the two N agree on every axis
    assert np.any((s.lines[1] > 16) & (s.lines[1] < 20)), s.lines
    assert model.components.sine(1) and 16 < model.components.sine(1)[0][1] < 20
    assert np.all(np.abs(ratio - 1) < 0.05), ratio


def test_plot_with_model_and_asd():
    from imunoise import plot

    y = imunoise.simulate(2**15, FS, N=1e-3, K=1e-4, channels=2, seed=1)
    s = imunoise.psd(y, FS)
    model = imunoise.fit(imunoise.adev(y, FS))
    fig = s.plot(model, unit="rad/s")
    assert len(fig.axes) == 2
    assert any(t.get_text().startswith("N = ") for t in fig.axes[0].texts)
    # one legend for the figure, below the panels (none inside a panel over the data)
    assert len(fig.legends) == 1 and all(ax.get_legend() is None for ax in fig.axes)
    fig = plot.spectrum(s, amplitude=True)
    assert "ASD" in fig.axes[0].get_ylabel()
    with pytest.raises(TypeError, match="Spectrum"):
        plot.spectrum(model)


def test_constant_and_tiny_channels_read_no_noise():
    # a dead axis next to a live one; values near 1e-144 (squares near the underflow)
    live = imunoise.simulate(4096, FS, N=1e-3, seed=1)
    s = imunoise.psd(np.column_stack([np.zeros(4096), live]), FS)
    assert s.N[0] == 0.0 and s.N[1] == pytest.approx(1e-3, rel=0.1)
    tiny = imunoise.psd(1e-144 * live, FS)
    assert tiny.N == pytest.approx(1e-147, rel=0.1)
    with pytest.raises(ValueError, match="too large for a spectrum"):
        imunoise.psd(1e200 * live, FS)


def test_plot_range_holds_every_panels_line():
    """The panels share y: a line that only one panel has (the 13.4 Hz line of the
    VN-100 live capture in gyro Y) must fit in the range, whichever panel is last."""
    from imunoise import plot

    fs = 40.0
    rng = np.random.default_rng(3)
    y = rng.standard_normal((2**15, 3)) * 1e-3
    t = np.arange(len(y)) / fs
    y[:, 1] += 2e-2 * np.sin(2 * np.pi * 13.4 * t)  # a strong line in the middle panel only
    s = imunoise.psd(y, fs)
    model = imunoise.fit(imunoise.adev(y, fs))
    fig = plot.spectrum(s, model, unit="rad/s")
    top = fig.axes[0].get_ylim()[1]
    highest = max(float(np.nanmax(line.get_ydata())) for ax in fig.axes[:3]
                  for line in ax.lines if line.get_label() == "PSD")
    assert highest < top, (highest, top)


def test_long_record_welch_by_groups_of_segments_is_scipys(monkeypatch):
    """A gap-free record with more segment samples than ``WELCH_PIECE`` is averaged a
    group of segments at a time (bounded memory): the periodogram of scipy's welch."""
    from scipy import signal

    y = np.random.default_rng(5).normal(size=(40_000, 3))
    monkeypatch.setattr(spectrum, "WELCH_PIECE", 3 * 4096)
    s = imunoise.psd(y, 100.0, nperseg=1024)
    f, p = signal.welch(y, fs=100.0, window="hann", nperseg=1024, noverlap=512, axis=0)
    np.testing.assert_allclose(s.f, f[1:])
    np.testing.assert_allclose(s.psd, p[1:], rtol=1e-12)
