"""The IG-500N still log that warms from 35.8 to 43.9 °C (../shared, not redistributable:
skipped without it): temperature, warm-up evidence and the thermal fit on real data."""

import warnings

import imunoise
import numpy as np
import pytest
from helpers.data import shared_file

#: 36,572 rows in a file named "static 2.44 h"; the rate is not documented.
FS = 36572 / (2.44 * 3600)


@pytest.fixture(scope="module")
def log():
    path = shared_file("data/other-imu/ig500n_static.txt")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return imunoise.read(path, fs=FS, columns={"gyro": [6, 7, 8], "accel": [3, 4, 5],
                                                   "temperature": 12},
                             units={"gyro": "deg/s"})


def test_temperature_settles_and_bias_shows_no_exponential_warm_up(log):
    found = imunoise.warmup(log)
    # the case heats with τ ≈ 12 min and is within 0.1 °C of its end after ≈ 55 min
    assert 600 < found.temperature_tau < 900
    assert found.temperature_final == pytest.approx(43.7, abs=0.2)
    assert 2400 < found.temperature_settle < 4200
    # its bias wander (level shifts of accel X) is not taken for a transient
    assert found.settle == 0


def test_thermal_fit_range_and_units(log):
    fit = imunoise.thermal(log)
    lo, hi = fit.temperature_range
    assert 35.5 < lo < 36.5 and 43.5 < hi < 44.0
    value, std, units = fit.datasheet()
    assert units[:3] == ("°/h/°C",) * 3 and units[3:] == ("mg/°C",) * 3
    assert np.all(np.isfinite(value)) and np.all(std > 0)
    # accel Z drifts down as it warms: a clear, signed sensitivity
    assert value[5] < 0 and abs(value[5]) > 3 * std[5]


def test_events_explain_the_heavy_tails(log):
    found = imunoise.events(log)
    assert 0 < found.share < 0.05
    z = log.accel[:, 2]
    kept = found.exclude(log).accel[:, 2]
    with_events = imunoise.distribution(z).excess_kurtosis
    without = imunoise.distribution(kept[np.isfinite(kept)]).excess_kurtosis
    assert with_events > 10 and abs(without) < 1
