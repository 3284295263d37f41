"""
Warm-up and temperature
=======================

A sensor that has just been switched on settles: its bias follows an exponential
transient, and a slow one reads as rate random walk at long taus. A bias that follows
the temperature does the same. :func:`imunoise.warmup` fits the transient and says when
the sensor settled; :func:`imunoise.thermal` fits the bias against temperature and
gives the compensated series.

The log is simulated: one hour at 10 Hz, a gyro whose bias decays with a 5-minute time
constant and follows a temperature that warms by 8 °C.
"""

import imunoise
import numpy as np
from imunoise import plot

fs = 10.0
t = np.arange(int(3600 * fs)) / fs
temperature = 30 + 8 * (1 - np.exp(-t / 900))
gyro = imunoise.simulate(t.size, fs, N=2e-4, B=1e-5, channels=3, seed=2)
gyro += 5e-4 * np.exp(-t / 300)[:, None]                   # warm-up transient
gyro += np.array([2e-5, -1e-5, 4e-5]) * (temperature - 34)[:, None]   # rad/s per °C
log = imunoise.ImuLog.from_arrays(fs, gyro=gyro, temperature=temperature)

# %%
# Warm-up
# -------
w = imunoise.warmup(log)
w

# %%
fig = plot.warmup(w)

# %%
# Bias against temperature
# ------------------------
th = imunoise.thermal(log)
th

# %%
fig = plot.thermal(th)

# %%
# The Allan deviation before and after the temperature compensation:
before = imunoise.adev(log.gyro, fs)
after = imunoise.adev(th.compensated, fs, taus=before.taus)
fig = plot.compensation(before, after, title="gyro: temperature compensation", unit="rad/s")
