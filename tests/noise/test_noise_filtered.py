"""A sensor's low-pass filter shapes the shortest taus: the Allan deviation rises
from the first tau to a hump and only then falls as white noise. That rising head
is neither a bias-instability floor (B) nor a rate random walk (K)."""

import warnings

import imunoise
import numpy as np
import pytest
from scipy.signal import butter, lfilter

FS = 1000.0
N_TRUE, B_TRUE = 1e-4, 2e-5


@pytest.fixture(scope="module")
def filtered():
    x = imunoise.simulate(300_000, FS, N=N_TRUE, B=B_TRUE, K=1e-6, channels=2, seed=1)
    b, a = butter(2, 100 / (FS / 2))  # a 100 Hz second-order low-pass, 5 min at 1 kHz
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = imunoise.adev(lfilter(b, a, x, axis=0), FS, taus=20)
        return r, imunoise.fit(r)


def test_the_curve_rises_before_it_falls(filtered):
    r, _ = filtered
    dev = r.dev[:, 0]
    assert dev[0] < 0.7 * dev.max()  # the filter's head: the premise of the tests below
    assert r.taus[np.argmax(dev)] < 0.02


def test_b_is_not_read_at_the_filters_head(filtered):
    r, model = filtered
    b = np.ravel(model.B)
    # NaN ("not resolved") or near the truth; the head's 5.5e-4 / 0.664 = 8e-4 was read before
    assert np.all(np.isnan(b) | (b < 3 * B_TRUE)), b
    assert np.all(np.ravel(model.N) == pytest.approx(N_TRUE, rel=0.15))


def test_the_read_off_takes_no_random_walk_from_the_head(filtered):
    _, model = filtered
    assert np.all(np.isnan(np.ravel(model.readoff["K"]["value"])))
    slopes = imunoise.fit(filtered[0], method="slopes")
    assert np.all(np.isnan(np.ravel(slopes.K)))
    assert np.all(np.ravel(slopes.upper["K"]) > 0)
