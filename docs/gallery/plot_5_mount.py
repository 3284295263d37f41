"""
Sensors on one mount
====================

Three gyros on one rocking mount see the same motion, far above their own noise:
each one's plain Allan deviation is the motion's. :func:`imunoise.align` puts their
logs on one time grid (here the sensors started at different times and stamp their
own clocks, so they are lined up on the motion), and :func:`imunoise.own_noise`
separates each gyro's own noise with the three-cornered hat.

The logs are simulated: one hour at 20 Hz, white noise of 0.01, 0.02 and 0.03
rad/s·√s under a 0.7 Hz rocking and a slow sway.
"""

import imunoise
import numpy as np
from imunoise import plot

fs, n = 20.0, 72_000
t = np.arange(n) / fs
motion = (imunoise.simulate(n, fs, gm=[(0.2, 5.0)], channels=3, seed=1)
          + 0.15 * np.sin(2 * np.pi * 0.7 * t)[:, None])
logs = []
for i, (white, start, clock) in enumerate(((0.01, 0, 0.0), (0.02, 300, 17.2),
                                           (0.03, 650, 3600.0))):
    gyro = motion[start:] + imunoise.simulate(n - start, fs, N=white, channels=3, seed=10 + i)
    logs.append(imunoise.ImuLog.from_arrays(fs, gyro=gyro, time=t[start:] + clock,
                                            source=f"gyro {i}"))

# %%
# One grid
# --------
aligned = imunoise.align(logs, clock="motion")
aligned

# %%
# Each gyro's own noise beside its plain deviation
# ------------------------------------------------
result = imunoise.own_noise(aligned, taus=np.geomspace(0.05, 10.0, 12))
fig = plot.own_noise(result, unit="rad/s")
