"""A burst is more power, not only another spectral shape: what the detector flags is
what a person sees in the time series (issue 26: the VN-100 live capture's gyro X
had events at 18.4 and 222.5 s whose RMS was 1.05 and 1.11 × the quiet level)."""

import imunoise
import numpy as np
import pytest
from scipy import signal

from tests.events.test_events import burst
from tests.helpers.data import shared_file


def _resonant_noise(n: int, fs: float, seed: int) -> np.ndarray:
    """Quiet noise dominated by a sensor's resonance: AR(2) with its pole at 17 Hz."""
    r, f0 = 0.9, 17.0
    a = [1.0, -2 * r * np.cos(2 * np.pi * f0 / fs), r * r]
    return signal.lfilter([1.0], a, np.random.default_rng(seed).standard_normal(n))


@pytest.mark.parametrize("seed", range(3))
def test_a_change_of_spectral_shape_at_the_same_power_is_not_a_burst(seed):
    fs, start, length = 40.0, 12_000, 80
    x = _resonant_noise(24_000, fs, seed)
    # 2 s of white noise at the record's own RMS: the whitening predictor does not
    # foresee it (its prediction errors rise) but nothing is louder
    x[start:start + length] = np.random.default_rng(seed + 100).standard_normal(length) * x.std()
    found = imunoise.events(x, fs)
    assert len(found) == 0, found.rows()


@pytest.mark.parametrize("seed", range(3))
def test_a_burst_in_resonant_noise_is_still_found(seed):
    fs, start, length = 40.0, 12_000, 60
    x = _resonant_noise(24_000, fs, seed)
    x[start:start + length] += burst(length, fs, 3.0 * x.std(), seed)
    found = imunoise.events(x, fs)
    assert len(found) == 1 and abs(found.start_index[0] - start) <= 4, found.rows()


def _adis_gyro_x() -> tuple[np.ndarray, float]:
    d = np.load(shared_file("data/other-imu/adis16405_static_2h47m.npz"))
    return d["gyro_counts"][:, 0] * float(d["gyro_scale_dps_per_count"]), float(
        d["sample_rate_hz"])


def test_quiet_adis16405_record_has_no_events_and_a_burst_put_in_is_found():
    x, fs = _adis_gyro_x()
    assert len(imunoise.events(x, fs)) == 0
    start, length = 500_000, 100
    y = x.astype(np.float64).copy()
    y[start:start + length] += burst(length, fs, 4.0 * x.std(), 0)
    found = imunoise.events(y, fs)
    assert len(found) == 1 and abs(found.start_index[0] - start) <= 10, found.rows()


def test_live_capture_events_are_louder_than_its_quiet_noise():
    log = imunoise.read(shared_file("data/vn100-ascii/live_capture.txt"), fs=40.0)
    found = imunoise.events(log)
    for t in (18.4, 222.5):  # RMS ×1.05, ×1.11: nothing to see
        assert not np.any((found.start <= t + 0.5) & (found.end >= t)), found.rows()
    for t in (79.0, 94.0, 137.0, 400.0, 742.0):  # visible bursts and the 324–477 s vibration
        assert np.any((found.start <= t) & (found.end >= t)), t


def test_rms_ratio_is_the_burst_against_the_quiet_noise():
    fs, start, length = 100.0, 30_000, 200
    rng = np.random.default_rng(4)
    x = rng.standard_normal(60_000)
    x[start:start + length] += 3.0 * rng.standard_normal(length)  # RMS √10 of the quiet 1
    found = imunoise.events(x, fs)
    (ratio,) = found.rms_ratio(x)[:, 0]
    assert ratio == pytest.approx(np.sqrt(10), rel=0.15)
    with pytest.raises(ValueError, match=r"\(60000 samples of x\); got 100 samples"):
        found.rms_ratio(x[:100])
    with pytest.raises(ValueError, match="baseline must be"):
        found.rms_ratio(x, baseline=-1.0)
