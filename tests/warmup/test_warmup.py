"""imunoise.warmup: settle time of simulated exponential transients, no transient in
stationary noise, trimming, and the K/R estimates after trimming."""

import imunoise
import numpy as np
import pytest

FS = 40.0


def transient_log(tau: float, seed: int, hours: float = 2.0, amplitude: float = 5e-4):
    rng = np.random.default_rng(seed)
    n = int(hours * 3600 * FS)
    t = np.arange(n) / FS
    return 8e-4 * rng.standard_normal(n) + amplitude * np.exp(-t / tau)


@pytest.mark.parametrize("tau", [300.0, 900.0, 1800.0])
def test_settle_time_within_20_percent(tau):
    x = transient_log(tau, seed=int(tau))
    found = imunoise.warmup(x, FS, tolerance=1e-5)
    truth = tau * np.log(5e-4 / 1e-5)
    assert found.significant[0]
    assert found.settle == pytest.approx(truth, rel=0.2)
    assert found.tau[0] == pytest.approx(tau, rel=0.2)
    # the stated uncertainty is an honest size of the error
    assert abs(found.settle - truth) < 4 * found.settle_time_std[0]


def test_stationary_noise_has_no_transient():
    rng = np.random.default_rng(1)
    x = imunoise.simulate(200_000, FS, N=1e-3, B=1e-5, channels=3, seed=rng)
    found = imunoise.warmup(x, FS)
    assert found.settle == 0 and not found.significant.any()
    assert found.settle_index == 0 and found.settled


def test_trim_cuts_at_the_settle_point_and_says_how_much():
    x = transient_log(600.0, seed=3)
    log = imunoise.ImuLog.from_arrays(FS, gyro=np.column_stack([x, x[::-1] * 0 + x, x]))
    found = imunoise.warmup(log, channels="gyro", tolerance=1e-5)
    cut = found.trim(log)
    assert len(cut) == len(log) - found.settle_index
    np.testing.assert_array_equal(cut.gyro, log.gyro[found.settle_index:])
    assert found.names == ("gyro X", "gyro Y", "gyro Z")
    assert "settled at" in repr(found) and len(repr(found)) <= 300
    assert repr(found).count("\n") <= 2 and "<table>" in found._repr_html_()
    assert [r["name"] for r in found.rows()] == list(found.names)


def test_constant_channel_never_needs_to_settle():
    x = np.zeros((20_000, 2))
    x[:, 1] = np.random.default_rng(0).standard_normal(20_000)
    found = imunoise.warmup(x, FS)
    assert found.settle == 0 and found.tolerance[0] == np.inf


def _fits_around_trimming(x, fs):
    """The warm-up found in ``x`` and the N + K + R models fitted before and after
    trimming it."""
    found = imunoise.warmup(x, fs)
    fits = [imunoise.fit(imunoise.adev(y, fs), terms=["N", "K", "R"], warn_coverage=False)
            for y in (x, found.trim(x))]
    return found, *fits


@pytest.mark.parametrize("seed", [11, 12])
def test_rate_random_walk_after_trimming_is_the_truth(seed):
    """A 4 h log with rate random walk K and a 20 min transient: the transient reads
    as twice the K before trimming; after it, K is within its uncertainty of the truth."""
    fs, hours, k_true = 10.0, 4.0, 5e-6
    n = int(hours * 3600 * fs)
    t = np.arange(n) / fs
    x = imunoise.simulate(n, fs, N=2e-3, K=k_true, seed=seed) + 3e-3 * np.exp(-t / 1200)
    found, before, after = _fits_around_trimming(x, fs)
    assert found.significant[0] and 0 < found.settle < 3 * 3600
    k_before, k_before_std = float(before.value("K")[0]), float(before.std("K")[0])
    assert k_before - k_true > 2 * k_before_std
    k_after, k_std = float(after.value("K")[0]), float(after.std("K")[0])
    assert abs(k_after - k_true) <= 2 * k_std


def test_temperature_evidence():
    x = transient_log(600.0, seed=5, hours=1.0)
    t = np.arange(len(x)) / FS
    temp = 44 - 8 * np.exp(-t / 700)
    found = imunoise.warmup(x, FS, temperature=temp, tolerance=1e-5)
    assert found.temperature_tau == pytest.approx(700, rel=0.05)
    assert found.temperature_final == pytest.approx(44, abs=0.05)
    assert found.temperature_settle == pytest.approx(700 * np.log(8 / 0.1), rel=0.05)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"block": -1}, "block must be positive"),
        ({"alpha": 2}, "alpha must be in"),
        ({"tolerance": -1.0}, "tolerance must be positive"),
        ({"block": 100.0}, "at least 20 blocks"),
        ({"temperature": np.zeros(3)}, "temperature must have 20000 samples"),
    ],
)
def test_bad_arguments(kwargs, message):
    with pytest.raises(ValueError, match=message):
        imunoise.warmup(np.zeros(20_000), FS, **kwargs)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_still_vn100_noise_with_rate_random_walk_has_no_transient(seed):
    """Rate random walk and flicker wander fit exponentials well by chance: the
    bootstrap null of the sensor's own noise must not call that a warm-up (an F-test
    gave p < 1e-10 on these logs and a settle point past their end)."""
    from imunoise._simulation.log import still_log

    log = still_log(5.0, 40.0, seed=seed)
    found = imunoise.warmup(log)
    assert not found.significant.any() and found.settle == 0
    assert np.mean(found.p_value > 0.01) >= 0.5  # p-values of stationary noise are not tiny


@pytest.mark.parametrize("seed", [1002, 1019])
def test_a_quiet_second_half_does_not_make_the_null_too_quiet(seed):
    """In these still logs the second half's random walk wandered so little that its
    point estimate of K is 0 on one gyro axis; a null built on it called that axis a
    warm-up (p = 5e-4). The null's K is the one the half cannot exclude (upper
    confidence limit of its Allan variance). The bound on p is well above the 5e-4
    of the too-quiet null and below what one of six uniform p-values reaches by
    chance on a few per cent of logs (seed 1019's Z gyro: 0.0045 since the rate
    ramp needs BIC evidence in the half log's model)."""
    from imunoise._simulation.log import still_log

    found = imunoise.warmup(still_log(5.0, 40.0, seed=seed))
    assert not found.significant.any()
    assert found.p_value.min() > 0.002


def test_settle_point_never_passes_the_end_of_the_log():
    x = transient_log(900.0, seed=7, hours=0.6, amplitude=5e-2)
    found = imunoise.warmup(x, FS, tolerance=1e-7)
    assert found.significant[0]
    assert found.settle == len(x) / FS and found.settle_index == len(x)
    assert len(found.trim(x)) == 0 and not found.settled


@pytest.mark.parametrize("seed", [11, 12])
def test_rate_ramp_after_trimming_is_the_truth(seed):
    """A 4 h log with a rate ramp R and a 20 min transient, no rate random walk: the
    transient reads as a K of 9σ before trimming (and R of 1–3× the truth); after it,
    R is within 2 standard uncertainties of the truth."""
    fs, hours, r_true = 10.0, 4.0, 1e-7
    n = int(hours * 3600 * fs)
    t = np.arange(n) / fs
    x = imunoise.simulate(n, fs, N=2e-3, R=r_true, seed=seed) + 1e-2 * np.exp(-t / 1200)
    found, before, after = _fits_around_trimming(x, fs)
    assert found.significant[0] and 0 < found.settle < 2 * 3600
    assert float(before.value("K")[0]) > 5 * float(before.std("K")[0])  # spurious: K = 0
    r_after, r_std = float(after.value("R")[0]), float(after.std("R")[0])
    assert abs(r_after - r_true) <= 2 * r_std
    assert abs(r_after - r_true) < abs(float(before.value("R")[0]) - r_true)
