"""
Events: spikes and bursts in a still log
========================================

A door slam or a footstep adds a burst that inflates the standard deviation and bends
the histogram. :func:`imunoise.events` finds spikes and bursts per channel against the
log's own noise; ``exclude`` turns them into missing samples, which the statistics and
the Allan deviation then skip.

The bundled VN-100 capture has a few short events of its own (it was recorded on a
desk); a 5-second burst is added to its gyro at 100 s to show a clear one.
"""

from importlib import resources

import imunoise
import numpy as np
from imunoise import plot

path = resources.files("imunoise") / "data" / "vn100_stationary_5min.txt"
log = imunoise.read(path, fs=40.0)
gyro = log.gyro.copy()
rng = np.random.default_rng(0)
burst = slice(4000, 4200)  # 5 s, from t = 100 s
gyro[burst] += 4 * gyro.std(axis=0) * rng.standard_normal((200, 3))
log = imunoise.ImuLog.from_arrays(log.fs, gyro=gyro, accel=log.accel)

found = imunoise.events(log)
found

# %%
# The report's figure: the channel with its events shaded and their peaks in σ.
fig = plot.events(log.gyro, found, log.fs, title="gyro with events", unit="rad/s")

# %%
# Without the events: the histograms the report draws beside the ones with them.
clean = found.exclude(log)
kept = [imunoise.distribution(clean.gyro[:, k][np.isfinite(clean.gyro[:, k])])
        for k in range(3)]
fig = plot.histograms(kept, title="gyro without events", unit="rad/s")
clean
