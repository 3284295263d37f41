"""imunoise.events: false alarms on white noise, bursts and spikes found where they
were put, the bundled VN-100 log's visible gyro X bursts, exclusion as missing samples."""

import warnings
from importlib import resources

import imunoise
import numpy as np
import pytest
from imunoise._analysis.events import FALSE_ALARM, Events

FS = 100.0
LOG = resources.files("imunoise") / "data" / "vn100_stationary_5min.txt"


def burst(n: int, fs: float, rms: float, seed: int) -> np.ndarray:
    """A vibration burst: a decaying 12 Hz oscillation plus broadband shaking."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    env = np.exp(-t / (0.4 * n / fs))
    return rms * env * (np.sqrt(2) * np.sin(2 * np.pi * 12 * t) + rng.standard_normal(n))


def test_white_noise_has_no_false_events_at_the_default_threshold():
    rng = np.random.default_rng(2024)
    x = rng.standard_normal((1_000_000, 3))
    found = imunoise.events(x, FS)
    # design rate 1e-7 per sample and channel: 0.3 expected here; 3 would be 10x over
    assert len(found) <= 2, found.rows()


def test_a_lower_threshold_raises_false_alarms_as_designed():
    rng = np.random.default_rng(7)
    x = rng.standard_normal(400_000)
    loose = imunoise.events(x, FS, false_alarm=1e-4)
    # 40 expected at the design rate (an upper bound by OVERLAP_FACTOR): between 4 and 80
    assert 4 <= len(loose) <= 80
    assert loose.spike_threshold < imunoise.events(x, FS).spike_threshold


@pytest.mark.parametrize("seed", range(5))
def test_burst_found_with_its_start_and_channel(seed):
    rng = np.random.default_rng(seed)
    x = rng.standard_normal((60_000, 3)) * [1.0, 2.0, 0.5]
    start = 20_000 + 977 * seed
    x[start:start + 150, 1] += burst(150, FS, 2.0 * 2.0, seed)
    found = imunoise.events(x, FS)
    assert len(found) == 1
    assert found.channels[0] == ("ch1",)
    assert found.kind[0] == "burst"
    assert abs(found.start[0] - start / FS) <= 0.1
    # the envelope decays into the noise (to 8 % at the end): the end is where it sinks
    assert start / FS + 0.3 <= found.end[0] <= (start + 150) / FS + 0.5
    assert found.peak[0] > 4


def test_spike_is_one_sample_with_its_size_in_sigmas():
    rng = np.random.default_rng(3)
    x = 0.01 * rng.standard_normal(50_000)
    x[12_345] += 0.12
    found = imunoise.events(x, FS)
    assert len(found) == 1 and found.kind == ("spike",)
    assert found.start_index[0] == 12_345 and found.end_index[0] == 12_346
    assert found.peak[0] == pytest.approx(12, abs=1.0)
    assert found.sigma[0] == pytest.approx(0.01, rel=0.03)


def test_slow_drift_and_missing_samples_do_not_change_the_events():
    rng = np.random.default_rng(4)
    n = 100_000
    noise = rng.standard_normal(n)
    noise[60_000:60_100] += burst(100, FS, 4.0, 0)
    drifting = noise + np.linspace(0, 30, n)  # 30 σ of drift over 1000 s
    drifting[40_000:40_500] = np.nan
    plain, found = imunoise.events(noise, FS), imunoise.events(drifting, FS)
    assert len(found) >= 1 and any(abs(s - 600) < 0.1 for s in found.start)
    assert np.array_equal(found.start_index, plain.start_index)
    assert np.array_equal(found.end_index, plain.end_index)
    np.testing.assert_allclose(found.peak, plain.peak, rtol=0.02)


def test_bundled_vn100_gyro_x_bursts_are_found():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        log = imunoise.read(LOG)
    found = imunoise.events(log, channels="gyro")
    gyro_x = [(a, b) for a, b, ch in zip(found.start, found.end, found.channels, strict=True)
              if "gyro X" in ch]
    for visible in (5, 90, 140, 185):
        assert any(a - 3 <= visible <= b + 3 for a, b in gyro_x), (visible, gyro_x)
    # and most of the log is left: the events are episodes, not the noise itself
    assert found.share < 0.2


def test_exclude_turns_events_into_gaps_the_allan_deviation_skips():
    rng = np.random.default_rng(5)
    clean = rng.standard_normal((200_000, 1))
    x = clean.copy()
    for k, s in enumerate((30_000, 90_000, 150_000)):
        x[s:s + 300, 0] += burst(300, FS, 15.0, k)
    found = imunoise.events(x, FS)
    assert len(found) == 3
    kept = found.exclude(x, pad=0.2)
    assert np.isnan(kept[found.mask]).all() and np.isfinite(kept[~found.padded_mask(0.2)]).all()
    taus = [0.01, 0.1, 1.0]
    dirty, cut, truth = (imunoise.adev(v, FS, taus=taus).dev[:, 0] for v in (x, kept, clean))
    assert np.all(np.abs(cut / truth - 1) < 0.03)
    assert np.all(dirty / truth > 1.05)


def test_exclude_on_a_log_makes_missing_rows_and_gaps():
    rng = np.random.default_rng(6)
    gyro = 1e-3 * rng.standard_normal((30_000, 3))
    gyro[10_000:10_100, 2] += 0.02
    log = imunoise.ImuLog.from_arrays(FS, gyro=gyro, accel=rng.standard_normal((30_000, 3)))
    found = imunoise.events(log)
    assert found.names == ("gyro X", "gyro Y", "gyro Z", "accel X", "accel Y", "accel Z")
    assert ("gyro Z",) in found.channels
    cut = found.exclude(log)
    assert len(cut.gaps) == len(found)
    assert cut.issues.samples_missing == int(found.mask.sum())
    assert np.isnan(cut.accel[found.mask]).all()


def test_result_summary_and_rows():
    rng = np.random.default_rng(8)
    x = rng.standard_normal(50_000)
    x[1000] = 40
    x[30_000:30_200] += burst(200, FS, 5, 1)
    found = imunoise.events(x, FS)
    assert isinstance(found, Events) and found.false_alarm == FALSE_ALARM
    text = repr(found)
    assert len(text) <= 300 and text.count("\n") <= 2
    assert "2 events (1 bursts, 1 spikes)" in text
    assert "<table>" in found._repr_html_()
    assert [r["kind"] for r in found.rows()] == ["spike", "burst"]
    assert np.all(found.duration > 0)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"fs": None}, "fs is required"),
        ({"fs": 100.0, "false_alarm": 0.5}, "false_alarm must be in"),
        ({"fs": 100.0, "window": -1}, "window must be positive"),
        ({"fs": 100.0, "merge": -1}, "merge must be >= 0"),
        ({"fs": 100.0, "channels": "gyro"}, "channels= selects log channels"),
        ({"fs": 1000.0}, "at least 2·window"),
    ],
)
def test_bad_arguments_are_named(kwargs, message):
    with pytest.raises(ValueError, match=message):
        imunoise.events(np.zeros(1000), **kwargs)


def test_log_channel_that_is_not_there():
    log = imunoise.ImuLog.from_arrays(FS, gyro=np.zeros((1000, 3)))
    with pytest.raises(ValueError, match=r"channels \['accel'\] are not in the log"):
        imunoise.events(log, channels="accel")


@pytest.mark.parametrize("runs", [0, 1, 7, 40])
def test_valid_pairs_count_every_pair_of_valid_samples(runs, monkeypatch):
    """The pairs of valid samples k apart behind the energy law's autocorrelation,
    counted from the runs of missing samples (or by FFT beyond PAIR_RUNS runs), are
    the brute-force counts."""
    from imunoise._analysis import events as _events

    rng = np.random.default_rng(runs)
    n, lags = 3000, 250
    valid = np.ones(n, dtype=bool)
    for a in rng.integers(0, n, runs):
        valid[a:a + rng.integers(1, 300)] = False  # runs may touch, overlap, end the record
    brute = np.array([np.sum(valid[:n - k] & valid[k:]) for k in range(lags)], dtype=float)
    np.testing.assert_array_equal(_events._valid_pairs(valid, lags), brute)
    monkeypatch.setattr(_events, "PAIR_RUNS", 0)
    np.testing.assert_allclose(_events._valid_pairs(valid, lags), brute, atol=1e-6)
