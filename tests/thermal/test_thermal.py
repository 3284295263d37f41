"""imunoise.thermal: coefficients recovered within 5 %, honest uncertainties, datasheet
units, the compensated series, errors."""

import imunoise
import numpy as np
import pytest

FS = 10.0
N = 72_000


def warming(seed: int, slope: float = 2e-5, curve: float = 0.0):
    rng = np.random.default_rng(seed)
    temp = 30 + 10 * (1 - np.exp(-np.arange(N) / FS / 1800))
    x = 1e-4 * rng.standard_normal(N) + slope * (temp - 35) + curve * (temp - 35) ** 2
    return x, temp


@pytest.mark.parametrize("seed", range(3))
def test_linear_coefficient_within_5_percent(seed):
    x, temp = warming(seed)
    fit = imunoise.thermal(x, temp, FS, sensor="gyro")
    assert fit.slope[0] == pytest.approx(2e-5, rel=0.05)
    assert abs(fit.slope[0] - 2e-5) < 4 * fit.coef_std[1, 0]
    value, std, units = fit.datasheet()
    assert units == ("°/h/°C",)
    assert value[0] == pytest.approx(2e-5 * 180 / np.pi * 3600, rel=0.05)
    lo, hi = fit.temperature_range
    assert 30 <= lo < 31 and 39 < hi <= 40


def test_quadratic_coefficient_and_accel_units():
    x, temp = warming(4, slope=1e-3, curve=2e-4)
    fit = imunoise.thermal(x, temp, FS, sensor="accel", degree=2, reference=35.0)
    assert fit.coef[1, 0] == pytest.approx(1e-3, rel=0.05)
    assert fit.coef[2, 0] == pytest.approx(2e-4, rel=0.05)
    value, _std, units = fit.datasheet(1)
    assert units == ("mg/°C",) and value[0] == pytest.approx(1e-3 / 9.80665 * 1000, rel=0.05)
    assert fit.datasheet(2)[2] == ("mg/°C²",)


def test_compensated_series_has_no_temperature_dependence():
    x, temp = warming(5, slope=5e-5)
    fit = imunoise.thermal(x, temp, FS)
    again = imunoise.thermal(fit.compensated, temp, FS)
    assert abs(again.slope[0]) < 3 * again.coef_std[1, 0]
    # the bias at the reference temperature is kept
    assert np.nanmean(fit.compensated) == pytest.approx(fit.coef[0, 0], abs=2e-6)


def test_log_with_temperature_and_correlated_residuals():
    rng = np.random.default_rng(6)
    temp = 30 + 10 * (1 - np.exp(-np.arange(N) / FS / 1800))
    wander = imunoise.simulate(N, FS, N=1e-4, K=1e-7, channels=3, seed=rng)
    gyro = wander + 2e-5 * (temp - 35)[:, None]
    log = imunoise.ImuLog.from_arrays(FS, gyro=gyro, temperature=temp)
    fit = imunoise.thermal(log)
    assert fit.names == ("gyro X", "gyro Y", "gyro Z") and fit.sensors == ("gyro",) * 3
    # the AR(1) inflation keeps the stated uncertainty a fair measure of the error
    assert np.all(np.abs(fit.slope - 2e-5) < 4 * fit.coef_std[1])
    assert fit.time_correlation > 0.7
    assert "°/h/°C" in repr(fit) and len(repr(fit)) <= 300
    assert "<table>" in fit._repr_html_()


@pytest.mark.parametrize(
    ("args", "kwargs", "message"),
    [
        ((np.zeros(N),), {"fs": FS}, "temperature is required"),
        ((np.zeros(N), np.full(N, 30.0)), {"fs": FS}, "temperature is constant"),
        ((np.zeros(N), np.zeros(5)), {"fs": FS}, "temperature must have"),
        ((np.zeros(N), np.arange(N, dtype=float)), {"fs": FS, "degree": 3}, "degree must be"),
        ((np.zeros(N), np.arange(N, dtype=float)), {"fs": FS, "sensor": "mag"}, "sensor must"),
    ],
)
def test_bad_arguments(args, kwargs, message):
    with pytest.raises(ValueError, match=message):
        imunoise.thermal(*args, **kwargs)


def test_log_without_temperature():
    log = imunoise.ImuLog.from_arrays(FS, gyro=np.zeros((1000, 3)))
    with pytest.raises(ValueError, match="no temperature channel"):
        imunoise.thermal(log)
