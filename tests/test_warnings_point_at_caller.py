"""The main API's warnings name the caller's file and line (issue #26: they pointed at
library lines such as readers/vn.py:304 or taus.py)."""

import warnings
from importlib import resources

import imunoise
import numpy as np


def _caught(call):
    """The warnings ``call()`` raises."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        call()
    assert caught, "no warning"
    return caught


def test_api_warnings_point_at_the_calling_line():
    log_path = str(resources.files("imunoise") / "data" / "vn100_stationary_5min.txt")
    x = np.random.default_rng(0).normal(size=4000)
    gapped = x.copy()
    gapped[1000:1010] = np.nan
    calls = {
        # no timestamps, no fs: the reader assumes 40 Hz (raised four calls down)
        "read": lambda: imunoise.read(log_path),
        # explicit taus out of range (taus.keep_estimable, below adev)
        "adev taus": lambda: imunoise.adev(x, 10.0, taus=[0.01, 1.0, 1e6]),
        # NaN spliced over (allan._gapped_samples)
        "adev splice": lambda: imunoise.adev(gapped, 10.0, gaps="splice"),
        # a window too short for a tau (dynamic._window_factors)
        "dynamic": lambda: imunoise.dynamic_adev(x, 1.0, window=100.0, taus=[1.0, 80.0]),
        # the deprecated positional bins (the decorator's wrapper)
        "deprecated": lambda: imunoise.distribution(x, 15),
    }
    for name, call in calls.items():
        caught = _caught(call)
        for w in caught:
            assert w.filename == __file__, (name, w.filename, w.lineno, str(w.message))
