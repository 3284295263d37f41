"""simulate_log writes a still VN-100 log that reads back with the datasheet's noise."""

import imunoise
import numpy as np
import pytest
from imunoise._simulation.log import flicker_for_floor, noise_of_spec, simulate_log, still_log
from imunoise.noise import FLICKER, model_variance


def _floor(terms):
    """σ_min/0.6643 of the model with these coefficients (the datasheet's B)."""
    taus = np.logspace(-3, 7, 20001)
    return np.sqrt(np.min(model_variance(taus, **terms))) / FLICKER


def test_noise_of_the_vn100_datasheet_in_si_units():
    noise = noise_of_spec("vn100")
    # 0.0035 °/s/√Hz and 10 °/h; 0.14 mg/√Hz and 0.04 mg
    assert noise["gyro"]["N"] == pytest.approx(0.0035 * np.pi / 180)
    assert noise["accel"]["N"] == pytest.approx(0.14e-3 * 9.80665)
    # B is the flicker coefficient whose Allan floor, N and K included, is the datasheet's
    assert _floor(noise["gyro"]) == pytest.approx(10 * np.pi / 180 / 3600, rel=1e-4)
    assert _floor(noise["accel"]) == pytest.approx(0.04e-3 * 9.80665, rel=1e-4)
    assert noise["gyro"]["B"] < 10 * np.pi / 180 / 3600
    # without the lift of N and K the coefficient is the floor itself
    assert flicker_for_floor(3e-5) == pytest.approx(3e-5)


def test_flicker_for_a_floor_the_other_terms_already_exceed_is_zero_with_a_warning():
    with pytest.warns(UserWarning, match="gyro: the datasheet's other terms alone put the Allan "
                                         "floor at .* above its bias instability 1e-06"):
        assert flicker_for_floor(1e-6, sensor="gyro", N=1e-4, K=1e-5) == 0.0


@pytest.mark.parametrize("fmt", ["vn-ascii", "vn-binary"])
def test_written_log_reads_back_with_the_specified_white_noise(tmp_path, fmt):
    path = simulate_log(tmp_path / "still.log", hours=0.25, fs=40.0, format=fmt, seed=3)
    log = imunoise.read(path, fs=40.0)
    assert len(log) == 36_000
    assert log.issues.total == 0
    assert np.mean(log.accel[:, 2]) == pytest.approx(-9.80665, abs=1e-3)
    model = imunoise.fit(imunoise.adev(log.gyro, log.fs), terms=("N", "B"))
    np.testing.assert_allclose(model.N, noise_of_spec()["gyro"]["N"], rtol=0.05)


def test_still_log_is_reproducible_and_validates():
    a = still_log(0.01, 40.0, seed=1)
    b = still_log(0.01, 40.0, seed=1)
    np.testing.assert_array_equal(a.gyro, b.gyro)
    with pytest.raises(ValueError, match="hours must be positive"):
        still_log(-1.0)
    with pytest.raises(ValueError, match="gives 0 samples"):
        still_log(1e-6, 40.0)
    # 3.6e9 samples grew until the kernel killed it; now refused before any allocation
    with pytest.raises(ValueError, match=r"gives 3\.6e\+09 samples; at most 10,000,000"):
        still_log(1000.0, 1000.0)
    with pytest.raises(ValueError, match="format must be one of vn-ascii, vn-binary; got 'csv'"):
        simulate_log("x.csv", 0.01, format="csv")
    with pytest.warns(DeprecationWarning, match="format to simulate_log"):
        with pytest.raises(ValueError, match="format must be one of"):
            simulate_log("x.csv", 0.01, 40.0, "csv")
