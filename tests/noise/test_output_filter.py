"""The sensor's output filter measured from the spectrum (`imunoise.noise._filter`)
and used by `imunoise.fit`: the core's c(τ) against an independent quadrature and the
tests' numpy oracle,
the gain of simulated filters recovered, no filter on white noise, N through a
filter, a log fitted directly."""

import math
import re
import warnings

import imunoise
import numpy as np
import pytest
from helpers.filter_oracle import density_allan, filter_factor  # the core's numpy oracle
from imunoise._core import fit as core_fit
from imunoise.errors import ImunoiseValueError
from imunoise.noise import OutputFilter, estimate_filter
from scipy import stats
from scipy.signal import butter, freqz, lfilter

FS = 100.0


def quadrature_factor(taus, fs, gain):
    """c(τ) by brute force: 1 + 2m∫(G − 1)·2 sin⁴(πνm)/(m² sin²πν) dν, G linear
    between its points, trapezoids fine enough for every period of sin⁴."""
    nu_grid = np.linspace(0.0, 0.5, gain.size)
    out = []
    for m in np.maximum(np.rint(np.asarray(taus) * fs), 1):
        nu = np.linspace(0.0, 0.5, int(max(200_000, 64 * m)) + 1)[1:]
        d = np.interp(nu, nu_grid, gain) - 1.0
        kernel = 2 * np.sin(np.pi * nu * m) ** 4 / (m * m * np.sin(np.pi * nu) ** 2)
        out.append(1 + 2 * m * np.trapezoid(d * kernel, nu))
    return np.array(out)


def butterworth_gain(order, cutoff, points):
    b, a = butter(order, cutoff / (FS / 2))
    _, h = freqz(b, a, worN=np.linspace(0, FS / 2, points), fs=FS)
    return np.abs(h) ** 2


GAINS = [butterworth_gain(4, FS / 10, 513), butterworth_gain(2, FS / 4, 257),
         np.r_[1.0, np.full(64, 0.5)],  # a step: G's corners
         np.linspace(1.0, 3.0, 33)]     # a rising gain


@pytest.mark.parametrize("gain", GAINS)
def test_filter_factor_is_the_quadrature(gain):
    """The core's c(τ) and the oracle's against brute-force trapezoids. Measured: both
    within 4·10⁻¹² of them, 3·10⁻⁹ on the step gain (the trapezoids' own error at its
    corner)."""
    taus = np.array([1, 2, 3, 5, 10, 31, 100, 400]) / FS
    want = quadrature_factor(taus, FS, gain)
    np.testing.assert_allclose(core_fit.filter_factor(taus, FS, gain), want, rtol=2e-6,
                               atol=1e-9)
    np.testing.assert_allclose(filter_factor(taus, FS, gain), want, rtol=2e-6, atol=1e-9)


def test_filter_factor_is_one_without_a_filter_and_at_long_taus():
    taus = np.geomspace(0.01, 1000.0, 25)
    np.testing.assert_array_equal(core_fit.filter_factor(taus, FS, np.ones(129)), 1.0)
    c = core_fit.filter_factor(taus, FS, butterworth_gain(4, FS / 10, 1025))
    assert c[0] < 0.1 and abs(c[-1] - 1) < 1e-4 and np.all(np.diff(c) > 0)


@pytest.mark.parametrize("gain", [butterworth_gain(3, FS / 6, 1025), *GAINS[2:],
                                  butterworth_gain(4, FS / 10, 32769)])
def test_core_filter_factor_agrees_with_the_numpy_oracle(gain):
    """The core's c(τ) against the oracle's: one exact formula (the piecewise-linear
    G's Fourier coefficients), two codes (rustfft and compensated running sums; numpy's
    FFT and cumsum), to the rounding of the sums up to m = 3·10⁵ (the longest tau of a
    5 h record at 40 Hz at a Welch grid of 32769 points)."""
    taus = np.r_[np.arange(1, 40), np.geomspace(40, 3e5, 40).round()] / FS
    np.testing.assert_allclose(core_fit.filter_factor(taus, FS, gain),
                               filter_factor(taus, FS, gain), rtol=1e-9, atol=1e-12)


def test_core_density_allan_agrees_with_the_numpy_oracle():
    """The filter's share of a flicker and walk level (any sign), as ``excess`` asks it."""
    f = np.linspace(0, FS / 2, 2049)
    low = np.r_[0.0, 1e-6 / f[1:] + 1e-8 / f[1:] ** 2]
    density = (butterworth_gain(4, FS / 10, f.size) - 1.0) * low
    taus = np.r_[np.arange(1, 20), np.geomspace(20, 1e5, 30).round()] / FS
    np.testing.assert_allclose(core_fit.density_allan(taus, FS, density),
                               density_allan(taus, FS, density), rtol=1e-9, atol=1e-20)


def test_density_allan_names_a_bad_density():
    with pytest.raises(ImunoiseValueError, match=re.escape("density[1] = NaN")):
        core_fit.density_allan(np.array([1.0]), FS, np.array([1.0, np.nan]))
    with pytest.raises(ImunoiseValueError, match="at least 2 values"):
        core_fit.density_allan(np.array([1.0]), FS, np.array([1.0]))


def filtered_noise(b, a, seed, n=360_000, channels=1):
    x = imunoise.simulate(n, FS, N=1e-3, B=3e-4, K=4e-5, channels=channels, seed=seed)
    return lfilter(b, a, x, axis=0)


def cic_gain(f, r=4, fs_in=4 * FS):
    # decimation by r folds the images of the band above fs/2 back in
    out = np.zeros_like(f)
    for k in range(-r, r + 1):
        g = np.abs(f + k * FS)
        ok = g <= fs_in / 2
        s = np.sin(np.pi * g[ok] / fs_in)
        out[ok] += np.where(s == 0, 1.0, (np.sin(np.pi * g[ok] * r / fs_in)
                                          / (r * np.where(s == 0, 1, s))) ** 6)
    return out


def cic_noise(seed, r=4):
    x = imunoise.simulate(360_000 * r, FS * r, N=1e-3, B=3e-4, K=4e-5, seed=seed)
    for _ in range(3):
        x = lfilter(np.ones(r) / r, [1.0], x)
    return x[r - 1::r]


def bartlett_taps(taps=11):
    h = np.bartlett(taps + 2)[1:-1]
    return h / h.sum()


CASES = {
    "butter2 fs/4": (lambda s: filtered_noise(*butter(2, 0.5), s),
                     lambda f: np.abs(freqz(*butter(2, 0.5), worN=f, fs=FS)[1]) ** 2),
    "butter4 fs/10": (lambda s: filtered_noise(*butter(4, 0.2), s),
                      lambda f: np.abs(freqz(*butter(4, 0.2), worN=f, fs=FS)[1]) ** 2),
    "cic3": (cic_noise, cic_gain),
    "bartlett": (lambda s: filtered_noise(bartlett_taps(), [1.0], s),
                 lambda f: np.abs(freqz(bartlett_taps(), [1.0], worN=f, fs=FS)[1]) ** 2),
}


@pytest.mark.parametrize("case", list(CASES))
def test_gain_of_a_simulated_filter_is_recovered_within_its_sampling_error(case):
    """Above the white region, where the filter is above 10⁻³: the shape of the
    measured G over |H|² stays within 4 standard errors of the running median (33
    Welch values, each χ²_ν/ν, correlated as Hann bins are) except on ≤ 1 % of the
    bins, and its common factor — the white level's error, whose standard uncertainty
    is 0.4–1.1 % here (measured: 0.3–1.6 %) — is within 3 %."""
    make, truth = CASES[case]
    s = imunoise.psd(make(7), FS)
    found = estimate_filter(s)
    assert found is not None
    g = truth(found.f)
    sel = (found.f > found.white_top) & (g > 1e-3)
    ratio = np.log(found.gain[sel] / g[sel])
    nu = float(np.median(s.edf))
    sigma = math.sqrt(math.pi / 2) * math.sqrt(2 * 1.9 / (33 * nu))
    assert np.mean(np.abs(ratio - np.median(ratio)) > 4 * sigma) <= 0.01
    assert abs(np.median(ratio)) < 0.03


@pytest.mark.parametrize("seed", range(10))
def test_no_filter_on_white_flicker_and_walk(seed):
    x = imunoise.simulate(200_000, FS, N=1e-3, B=3e-4 * (seed % 2), K=4e-5 * (seed % 3 > 0),
                          seed=100 + seed)
    assert estimate_filter(imunoise.psd(x, FS)) is None


def test_false_filters_are_rare_on_white_noise():
    """FALSE_FILTER is a familywise 5 %: on 40 white records, at most 5 filters (the
    binomial 99.9 % quantile of 40 × 5 % is 6)."""
    x = imunoise.simulate(100_000, FS, N=1e-3, channels=40, seed=11)
    s = imunoise.psd(x, FS)
    found = sum(estimate_filter(s, c) is not None for c in range(40))
    assert found <= stats.binom.ppf(0.999, 40, 0.05) - 1


def test_a_fast_gauss_markov_bias_is_no_filter():
    """A bias of τc 1 s over white noise has a low-pass's shape (its plateau falls
    to the white floor above 0.16 Hz), but two and a half decades below fs/2: the
    Gauss–Markov term's, not an output filter's."""
    from scipy.signal import lfilter as ar

    rng = np.random.default_rng(4)
    phi = math.exp(-1 / FS)
    bias = ar([1.0], [1.0, -phi], rng.standard_normal(360_000) * 1e-2 * math.sqrt(1 - phi**2))
    x = imunoise.simulate(360_000, FS, N=1e-3, seed=4) + bias
    assert estimate_filter(imunoise.psd(x, FS)) is None


def test_a_shelf_below_fs_2_is_no_filter():
    """A fast Gauss–Markov term (τc 4 samples, its shoulder a decade below fs/2, at a
    zero-frequency level 0.3 of the white) over white noise: the spectrum falls by a
    quarter to a shelf, where an output filter would keep attenuating up to fs/2 (a
    parked ring-laser gyro's vibration hump over its mount's motion had been taken
    for a filter, and the fit then lost the motion)."""
    rng = np.random.default_rng(8)
    phi = math.exp(-1 / 4)
    sigma = math.sqrt(0.3 * (1 - phi) / (1 + phi))
    white = rng.standard_normal((360_000, 3))
    hump = lfilter([1.0], [1.0, -phi], rng.standard_normal((360_000, 3)), axis=0)
    s = imunoise.psd(white + sigma * math.sqrt(1 - phi**2) * hump, FS)
    assert all(estimate_filter(s, c) is None for c in range(3))
    # white noise through a first-order low-pass, which keeps falling: a filter
    b, a = butter(1, 0.3)
    s = imunoise.psd(lfilter(b, a, white, axis=0), FS)
    assert all(estimate_filter(s, c) is not None for c in range(3))


def test_no_filter_on_a_rising_quantization_floor():
    """Counted angles (quantization's f² above the white region) are no filter: an
    output filter attenuates; the rise is the Q term's."""
    x = imunoise.simulate(360_000, FS, Q=2e-5, N=1e-3, seed=3)
    assert estimate_filter(imunoise.psd(x, FS)) is None


def test_a_line_is_no_filter():
    t = np.arange(360_000) / FS
    x = imunoise.simulate(360_000, FS, N=1e-3, seed=5) + 0.02 * np.sin(2 * np.pi * 23.4 * t)
    assert estimate_filter(imunoise.psd(x, FS)) is None


def test_n_through_a_butterworth_filter_is_within_5_percent():
    """A 4th-order Butterworth at fs/10 (an IMU's output filter): the datasheet N of
    each axis within 5 % of the white input's, no tone or resonance reported, the
    measured filter kept on the model and used by its prediction."""
    x = filtered_noise(*butter(4, 0.2), seed=21, channels=3)
    log = imunoise.ImuLog.from_arrays(FS, gyro=x)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = imunoise.fit(log)
    assert np.all(np.abs(np.asarray(model.N) / 1e-3 - 1) < 0.05)
    assert all(f is not None for f in model.filter)
    for c in range(3):
        assert not any(isinstance(t, imunoise.noise.Resonance) for t in model.terms[c])
        assert not [ln for ln in model.lines[c] if ln.reported]
    assert any("output filter measured" in note for note in model.notes[0])
    assert np.all(np.asarray(model.coverage) >= 0.95)


def test_an_allan_result_alone_keeps_the_fit_and_says_so():
    x = imunoise.simulate(100_000, FS, N=1e-3, B=3e-4, seed=2)
    r = imunoise.adev(x, FS, taus=10)
    model = imunoise.fit(r)
    assert model.filter == (None,)
    assert any("not taken from a spectrum" in note for note in model.notes[0])
    same = imunoise.fit(r, spectrum=imunoise.psd(x, FS), output_filter=False)
    np.testing.assert_array_equal(np.asarray(same.N), np.asarray(model.N))
    assert not any("spectrum" in note for note in same.notes[0])


def test_a_log_without_the_sensor_names_it():
    log = imunoise.ImuLog.from_arrays(FS, accel=np.zeros((1000, 3)))
    with pytest.raises(ImunoiseValueError, match="no gyro channel; pass sensor='accel'"):
        imunoise.fit(log)
    with pytest.raises(ImunoiseValueError, match="sensor must be 'gyro' or 'accel'; got 'mag'"):
        imunoise.fit(log, sensor="mag")


def test_output_filter_repr_and_factor():
    found = OutputFilter(f=np.linspace(0, 50, 5), gain=np.array([1, 1, 0.5, 0.1, 0.0]), fs=FS,
                         white_top=12.5, white=2e-6)
    assert "white to 12.5 Hz" in repr(found)
    np.testing.assert_allclose(found.factor([0.01, 100.0]),
                               filter_factor([0.01, 100.0], FS, found.gain), rtol=1e-9)


def test_the_filter_travels_in_the_models_dict():
    import json

    fs, n = 200.0, 400_000
    b, a = butter(4, fs / 10, fs=fs)
    x = lfilter(b, a, imunoise.simulate(n, fs, N=1e-3, B=1e-5, seed=21))
    model = imunoise.fit(imunoise.adev(x, fs, taus=10), spectrum=imunoise.psd(x, fs))
    d = json.loads(json.dumps(model.to_dict()))
    assert d["filter"][0]["white_top"] == pytest.approx(model.filter[0].white_top)
    assert d["filter"][0]["gain"][-1] < 0.1  # a 4th-order low-pass at fs/10: nothing at fs/2


def test_apply_gives_white_noise_the_filters_allan_variance():
    """``OutputFilter.apply`` (a bootstrap's replicates through the sensor's filter):
    white noise through it has the Allan variance (N²/τ)·c(τ) the core fits."""
    gain = butterworth_gain(4, FS / 10, 513)
    found = OutputFilter(f=np.linspace(0, FS / 2, gain.size), gain=gain, fs=FS,
                         white_top=1.0, white=2e-6)
    x = imunoise.simulate(400_000, FS, N=1e-3, channels=2, seed=4)
    y = found.apply(x)
    assert y.shape == x.shape
    np.testing.assert_array_equal(found.apply(x[:, 0]), y[:, 0])
    r = imunoise.adev(y, FS, taus=np.array([0.01, 0.02, 0.05, 0.1, 1.0]))
    want = 1e-6 / r.taus * found.factor(r.taus)
    # each within 4 of its own standard errors (EDF of the overlapping estimates)
    z = (r.var / want[:, None] - 1) / np.sqrt(2 / r.edf)
    assert np.all(np.abs(z) < 4), z


def test_a_bootstrap_simulates_and_refits_through_the_point_fits_filter(monkeypatch):
    from imunoise.noise import _fit as fit_module

    b, a = butter(4, 0.2)
    x = filtered_noise(b, a, seed=8, n=100_000)
    r, s = imunoise.adev(x, FS, taus=10), imunoise.psd(x, FS)
    applied, refits = [], []
    real_apply, real_fit = OutputFilter.apply, fit_module._fit

    def spy_apply(self, y):
        applied.append(self)
        return real_apply(self, y)

    def spy_fit(result, **kwargs):
        if result is not r:  # a replicates' refit
            refits.append(kwargs.get("filters"))
        return real_fit(result, **kwargs)

    monkeypatch.setattr(OutputFilter, "apply", spy_apply)
    monkeypatch.setattr(fit_module, "_fit", spy_fit)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = imunoise.fit(r, spectrum=s, uncertainty="bootstrap", replicates=5, seed=0)
    found = model.filter[0]
    assert found is not None
    assert applied == [found]
    assert len(refits) == 1 and refits[0] == (found,) * 5
    # the core's terms, their uncertainties the bootstrap's
    plain = imunoise.fit(r, spectrum=s)
    assert len(model.terms[0]) == len(plain.terms[0])
    for boot, core in zip(model.terms[0], plain.terms[0], strict=True):
        values = {k: v for k, v in boot.to_dict().items() if not k.endswith("_std")}
        assert values == {k: v for k, v in core.to_dict().items() if not k.endswith("_std")}
    white = [next(t for t in m.terms[0] if isinstance(t, imunoise.noise.White))
             for m in (model, plain)]
    assert np.isfinite(white[0].N_std) and white[0].N_std != white[1].N_std


def test_n_std_carries_the_white_levels_uncertainty():
    """Through a filter, N follows the white level G was measured against (G's common
    factor), so N_std carries that level's uncertainty (``OutputFilter.white_std``,
    propagated by the core's covariance). Over 8 records of a 4th-order Butterworth at
    fs/10 (1 h at 100 Hz each, the structure N + B + K given: the selection's own
    choices are not this test's) the z-scores (N − N_true)/N_std have an rms near 1:
    measured 1.22 here and 1.02 over 32 other records; 4.8 and 4.1 when N_std left the
    level out."""
    z, share = [], []
    for seed in range(8):
        x = filtered_noise(*butter(4, 0.2), seed=100 + seed)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = imunoise.fit(imunoise.adev(x, FS, taus=10), spectrum=imunoise.psd(x, FS),
                                 terms=["N", "B", "K"])
        found = model.filter[0]
        assert found is not None and 0 < found.white_std < 0.05
        z.append((float(model.N) - 1e-3) / float(model.N_std))
        white = next(t for t in model.terms[0] if isinstance(t, imunoise.noise.White))
        share.append(white.N_std / white.N)
    z = np.array(z)
    assert np.sqrt(np.mean(z**2)) < 1.6 and np.all(np.abs(z) < 3.5), z
    # the level's part dominates u(N) here (the sampling part alone is ≈ 0.12 %)
    assert np.median(share) > 0.003, share


def test_b_is_read_off_the_curve_the_model_draws_through_its_filter():
    # a floor at short taus, where a low-pass at fs/10 still lowers the white
    # noise: B, the floor the plot marks and the predicted curve are one number
    fs = 200.0
    x = imunoise.simulate(int(fs * 1200), fs, N=3e-4, B=2e-3, K=7e-3, channels=2, seed=3)
    b, a = butter(2, 20 / (fs / 2))
    x = lfilter(b, a, x, axis=0)
    r = imunoise.adev(x, fs, taus=20)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = imunoise.fit(r, spectrum=imunoise.psd(x, fs))
    flicker = math.sqrt(2 * math.log(2) / math.pi)
    for c in range(2):
        assert m.filter[c] is not None
        tau, sigma = m.floor(c)
        assert tau > 5 / fs  # past the filter's head, not on it
        assert m.B[c] == pytest.approx(sigma / flicker, rel=1e-12)
        # the drawn curve is the floor's plus the flicker's share the filter takes
        drawn = m.predict([tau]).dev[0, c]
        assert drawn**2 == pytest.approx(sigma**2 + m.filter[c].excess([tau])[0], rel=1e-9)
        unfiltered = core_fit.model_floor([t.core() for t in m.terms[c]],
                                          np.ascontiguousarray(m.taus), fs)
        assert unfiltered[1] > sigma * 1.005  # the filter lowers the floor here


def test_the_upper_bound_on_n_holds_through_a_filter():
    # a low-pass lowers the short taus' variance below N²/τ: a bound read off
    # 1/τ there would lie below the sensor's N; read off c(τ)/τ it holds
    from imunoise.noise._datasheet import upper_bounds

    n_true = 1e-3
    x = imunoise.simulate(200_000, FS, N=n_true, channels=2, seed=4)
    b, a = butter(4, 5 / (FS / 2))
    x = lfilter(b, a, x, axis=0)
    r = imunoise.adev(x, FS, taus=20)
    found = [estimate_filter(imunoise.psd(x, FS), c) for c in range(2)]
    assert all(f is not None for f in found)
    blind = upper_bounds(r.taus, r.dev**2, r.edf)["N"]
    seen = upper_bounds(r.taus, r.dev**2, r.edf, found)["N"]
    assert np.all(blind < 0.5 * n_true)
    assert np.all(seen >= n_true) and np.all(seen < 1.2 * n_true)


def test_the_running_median_is_each_reflected_windows_middle_value():
    from imunoise.noise._filter import HALF_WIDTH, _running_median

    rng = np.random.default_rng(5)
    for n in (2 * HALF_WIDTH + 1, 2 * HALF_WIDTH + 2, 1000):
        p = rng.chisquare(8, n)
        padded = np.pad(p, HALF_WIDTH, mode="reflect")
        windows = np.lib.stride_tricks.sliding_window_view(padded, 2 * HALF_WIDTH + 1)
        assert np.array_equal(_running_median(p, HALF_WIDTH), np.median(windows, axis=1))
