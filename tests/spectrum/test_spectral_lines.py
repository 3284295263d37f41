"""A tone is reported as a line only where the spectrum shows one: a real line is found
at the spectrum's frequency, a filter's roll-off is never taken for one, and the model's
resonance has the PSD its Allan variance implies."""

from __future__ import annotations

import math
import warnings

import imunoise
import numpy as np
import pytest
from helpers.data import shared_file
from imunoise import spectral_lines
from imunoise.noise._terms import resonance_white_density
from imunoise.spectrum import resonance_psd
from scipy import signal

FS = 100.0


def _white(seconds: float, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).standard_normal((int(seconds * FS), 3))


def _quiet_fit(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return imunoise.fit(*args, **kwargs)


def test_a_line_at_half_the_white_rms_is_found_at_the_spectrums_frequency():
    w = _white(1800, 3)
    t = np.arange(w.shape[0]) / FS
    phases = np.random.default_rng(4).uniform(0, 2 * np.pi, 3)
    x = w + 0.5 * math.sqrt(2) * np.sin(2 * np.pi * 23.4 * t[:, None] + phases)
    s = imunoise.psd(x, FS)
    model = _quiet_fit(imunoise.adev(x, FS, taus=20), spectrum=s)
    for c in range(3):
        reported = [line for line in model.lines[c] if line.reported]
        assert len(reported) == 1, model.lines[c]
        line = reported[0]
        assert line.in_spectrum and line.ratio > 100 * line.threshold
        assert line.frequency == pytest.approx(23.4, rel=0.002)
        # one model: the tone is at the spectrum's frequency, its variance fitted there
        (tone,) = [t for t in model.terms[c] if t.kind == "tone"]
        assert tone.freq == line.frequency
        assert tone.amplitude == line.amplitude
    assert "tone 23.4 Hz" in repr(model)
    from imunoise.report import model_text

    said = " ".join(model_text.model_sentences(model, "gyro"))
    assert said.count("a line of amplitude") == 3, said


def test_the_search_reaches_the_allan_fits_interval_of_the_frequency():
    # a line at 1.2 Hz that an Allan fit placed 8 % high with a standard
    # uncertainty of 5 %: outside the 5 % search, inside the fit's 95 % interval
    w = _white(1800, 5)
    t = np.arange(w.shape[0]) / FS
    s = imunoise.psd(w + 0.3 * np.sin(2 * np.pi * 1.2 * t[:, None]), FS)
    for c in range(3):
        assert not spectral_lines.check_line(s, c, 1.3).in_spectrum
        line = spectral_lines.check_line(s, c, 1.3, f0_std=0.06)
        assert line.in_spectrum and line.frequency == pytest.approx(1.2, abs=0.005)
        # an interval wider than the frequency's half searches only to half of it
        assert not spectral_lines.check_line(s, c, 2.5, f0_std=2.0).in_spectrum


def _filtered(kind: str, w: np.ndarray) -> np.ndarray:
    if kind == "cic":  # a sinc³ decimator's response, before decimation
        y = w
        for _ in range(3):
            y = signal.lfilter(np.ones(4) / 4, [1.0], y, axis=0)
        return y
    if kind == "bartlett":
        taps = signal.windows.bartlett(9)
        return signal.lfilter(taps / taps.sum(), [1.0], w, axis=0)
    order, cutoff = kind
    b, a = signal.butter(order, cutoff / (FS / 2))
    return signal.lfilter(b, a, w, axis=0)


@pytest.mark.parametrize("kind", [(2, 25.0), (3, 15.0), (4, 10.0), "cic", "bartlett"])
def test_a_filters_roll_off_is_never_a_line(kind):
    """Output filters no model term describes: whatever tone the Allan fit draws to
    follow their roll-off, the spectrum shows no line, on a grid of probes either."""
    y = _filtered(kind, _white(1200, 11))
    s = imunoise.psd(y, FS)
    model = _quiet_fit(imunoise.adev(y, FS, taus=20), spectrum=s)
    for c in range(3):
        assert not any(line.reported for line in model.lines[c]), model.lines[c]
        for f0 in np.arange(1.0, 48.0, 1.3):
            assert not spectral_lines.check_line(s, c, f0).in_spectrum, f0
    assert "tone" not in repr(model)


def test_without_a_spectrum_tones_are_reported_unchecked():
    w = _white(600, 5)
    t = np.arange(w.shape[0]) / FS
    x = w + math.sqrt(2) * np.sin(2 * np.pi * 7.3 * t)[:, None]
    model = _quiet_fit(imunoise.adev(x, FS, taus=20))
    lines = [line for c in range(3) for line in model.lines[c]]
    assert lines and all(line.in_spectrum is None and line.reported for line in lines)
    assert all(line.frequency == line.allan_frequency for line in lines)


def test_the_vn100_capture_keeps_its_line():
    log = imunoise.read(shared_file("data/vn100-ascii/live_capture.txt"), fs=40.0)
    s = imunoise.psd(log.gyro, log.fs)
    model = _quiet_fit(imunoise.adev(log.gyro, log.fs, taus=20), spectrum=s)
    found = [line.frequency for c in range(3) for line in model.lines[c] if line.in_spectrum]
    assert any(abs(f - 13.4) < 0.2 for f in found), model.lines


def test_the_spectrum_must_match_the_result():
    x = _white(300, 1)
    r = imunoise.adev(x, FS, taus=10)
    with pytest.raises(TypeError, match="spectrum must be a Spectrum"):
        imunoise.fit(r, spectrum=np.ones(3))
    with pytest.raises(ValueError, match="spectrum has 1 channels; the Allan result has 3"):
        imunoise.fit(r, spectrum=imunoise.psd(x[:, 0], FS))
    with pytest.raises(ValueError, match=r"spectrum.fs must equal result.fs \(100.0 Hz\)"):
        imunoise.fit(r, spectrum=imunoise.psd(x, 50.0))
    with pytest.raises(ValueError, match="linear grid"):
        imunoise.fit(r, spectrum=imunoise.psd(x, FS).smooth())


@pytest.mark.parametrize("skew", [0.0, 0.6, -1.0])
def test_the_resonance_psd_is_its_allan_variances(skew):
    """It integrates to σ² (Parseval) and is 2N² at 0 Hz, the white tail its Allan
    variance has beyond τr."""
    f = np.linspace(0.0, 20.0, 400_001)
    p = resonance_psd(2.0, 13.0, 0.3, skew, f, 40.0)
    assert np.all(p >= 0)
    assert np.trapezoid(p, f) == pytest.approx(4.0, rel=1e-6)
    white = resonance_white_density(2.0, 13.0, 0.3, 40.0, skew)
    assert p[0] == pytest.approx(2 * white, rel=1e-9, abs=1e-15)


def test_a_slope_next_to_0_hz_is_no_line():
    # a random walk's spectrum rises as 1/f² toward 0 Hz: a peak within a few bins
    # of it has a background on one side only, which stands far below it
    rng = np.random.default_rng(6)
    x = rng.standard_normal((180_000, 3)) + 0.05 * np.cumsum(rng.standard_normal((180_000, 3)), 0)
    s = imunoise.psd(x, FS)
    df = s.f[1] - s.f[0]
    for c in range(3):
        for bins in (3, 5, 8, 12):
            assert not spectral_lines.check_line(s, c, bins * df).in_spectrum, bins
