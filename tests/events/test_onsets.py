"""Burst onsets next to what a real record holds: an outlier just before the burst,
heavy-tailed noise, a loud stretch elsewhere in the record, a short burst."""

import imunoise
import numpy as np
import pytest

from tests.events.test_events import burst


def _onset_found(found, start: int, stop: int, fs: float) -> bool:
    """A burst event overlaps [start, stop) and begins within 0.1 s of ``start``."""
    hit = [i for i in range(len(found))
           if found.kind[i] == "burst" and found.start_index[i] < stop
           and found.end_index[i] > start]
    return bool(hit) and abs(found.start_index[hit[0]] - start) / fs <= 0.1


@pytest.mark.parametrize("seed", range(4))
def test_an_outlier_before_a_burst_stays_a_spike_of_its_own(seed):
    fs = 100.0
    x = np.random.default_rng(seed).standard_normal(60_000)
    start = 30_000
    x[start - 30] += 12.0  # a glitch 0.3 s before the burst (within the 0.5 s merge gap)
    x[start:start + 150] += burst(150, fs, 4.0, seed)
    found = imunoise.events(x, fs)
    spikes = [i for i in range(len(found)) if found.kind[i] == "spike"]
    assert [found.start_index[i] for i in spikes] == [start - 30]
    assert _onset_found(found, start, start + 150, fs), found.rows()


def test_heavy_tailed_noise_does_not_pull_a_burst_start_forward():
    # Student-t (ν = 3) noise: large samples are common, as on the MTi-G gyro
    fs = 100.0
    rng = np.random.default_rng(11)
    x = rng.standard_t(3, 400_000)
    starts = np.arange(20, 390, 10) * 1000 + rng.integers(0, 500, 37)
    for k, s in enumerate(starts):
        x[s:s + 120] += burst(120, fs, 4.0 * np.sqrt(3.0), k)  # 4 × the RMS of t(3)
    found = imunoise.events(x, fs)
    share = np.mean([_onset_found(found, s, s + 120, fs) for s in starts])
    assert share >= 0.9, share


def _vibration(n: int, fs: float, hz: float, rng) -> np.ndarray:
    """Narrow-band noise around ``hz`` (an AR(2) resonance), unit RMS."""
    r, theta = 0.97, 2 * np.pi * hz / fs
    e = rng.standard_normal(n + 500)
    y = np.zeros_like(e)
    for i in range(2, len(e)):
        y[i] = 2 * r * np.cos(theta) * y[i - 1] - r * r * y[i - 2] + e[i]
    return y[500:] / np.std(y[500:])


def test_a_vibrating_stretch_elsewhere_does_not_blind_the_quiet_part():
    # 40 Hz, like the VN-100 live capture: a fifth of the record vibrates at 3× the
    # quiet RMS; bursts go into the quiet part
    fs = 40.0
    rng = np.random.default_rng(12)
    n = 40_000
    x = rng.standard_normal(n)
    x[16_000:24_000] += 3.0 * _vibration(8_000, fs, 6.0, rng)
    starts = np.arange(2, 15) * 1000 + 200
    for k, s in enumerate(starts):
        x[s:s + 30] += burst(30, fs, 3.5, k)  # 0.75 s, 3.5 × the quiet RMS
    found = imunoise.events(x, fs)
    hit = [bool(np.any((found.start_index < s + 30) & (found.end_index > s))) for s in starts]
    onset = [_onset_found(found, s, s + 30, fs) for s in starts]
    # with the noise law of the whole record (vibration included) 2 of 13 were found
    assert all(hit), found.rows()[:5]
    assert np.mean(onset) >= 0.8, found.rows()[:5]
    # the vibrating stretch is an event itself
    assert found.mask[17_000:23_000].mean() > 0.8


def test_a_short_burst_is_not_diluted_in_the_energy_window():
    fs = 40.0
    shares = []
    for seed in range(3):
        rng = np.random.default_rng(seed)
        x = rng.standard_normal(60_000)
        starts = np.arange(2, 58) * 1000 + 300
        for k, s in enumerate(starts):
            x[s:s + 14] += burst(14, fs, 4.0, k + 100 * seed)  # 0.35 s at 40 Hz
        found = imunoise.events(x, fs)
        shares += [bool(np.any((found.start_index < s + 14) & (found.end_index > s)))
                   for s in starts]
    # one 1 s window finds 79 % of them; windows of 1, 0.5 and 0.25 s 86 %
    assert np.mean(shares) >= 0.84


def test_raised_noise_just_before_a_burst_does_not_become_its_start():
    # 40 Hz: 0.5 s of noise at 1.3× the quiet RMS (below detection) just before each
    # decaying burst, as on the VN-100 live capture, where the burst's diluted
    # variance let such stretches in (starts 0.1–1.4 s early there). The start is a
    # change point: some early starts remain by chance, about 14 % here. With the
    # variance of the burst's first quarter 59 % were within 0.1 s, 55 % on seed 22.
    fs = 40.0
    rng = np.random.default_rng(21)
    x = rng.standard_normal(80_000)
    starts = np.arange(2, 78) * 1000 + rng.integers(0, 400, 76)
    for k, s in enumerate(starts):
        x[s - 20:s] *= 1.3
        n = int(rng.uniform(0.5, 2.5) * fs)
        x[s:s + n] += burst(n, fs, rng.uniform(3.0, 5.0), k)
    found = imunoise.events(x, fs)
    share = np.mean([_onset_found(found, s, s + 20, fs) for s in starts])
    assert share >= 0.75, share


def test_a_shock_during_a_vibration_is_an_event_of_its_own():
    # 40 Hz: 200 s of a 9 Hz vibration at 3× the quiet RMS, with five shocks in it
    fs = 40.0
    rng = np.random.default_rng(4)
    x = rng.standard_normal(24_000)
    x[2_000:10_000] += 3.0 * _vibration(8_000, fs, 9.0, rng)
    shocks = [3_100, 4_700, 6_000, 7_400, 8_900]
    for k, s in enumerate(shocks):
        x[s:s + 40] += burst(40, fs, 12.0, k)  # 1 s, about 4× the vibration's RMS
    found = imunoise.events(x, fs)
    parent = int(np.argmax(found.duration))
    assert found.start_index[parent] <= 2_040 and found.end_index[parent] >= 9_960
    inside = np.flatnonzero(found.within == parent)
    starts = found.start_index[inside]
    assert all(np.min(np.abs(starts - s)) <= 4 for s in shocks), found.rows()
    assert len(inside) == len(shocks)
    assert "5 inside longer ones" in repr(found)
    assert found.rows()[inside[0]]["within"] == parent


def test_a_steady_vibration_holds_no_events_inside_it():
    fs = 40.0
    nested = 0
    for seed in range(6):
        rng = np.random.default_rng(100 + seed)
        x = rng.standard_normal(30_000)
        x[5_000:25_000] += 3.0 * _vibration(20_000, fs, 4.0 + 2 * seed, rng)
        nested += int(np.count_nonzero(imunoise.events(x, fs).within >= 0))
    assert nested == 0
