"""
The lab: from a raw VN-100 log to the coefficient table
=======================================================

The classic IMU noise lab in a few calls: read the raw ``$VNYMR`` log of a still
VectorNav VN-100, look at it, take the sample statistics, compute the Allan deviation
with confidence intervals, fit the noise model, print the coefficients in datasheet
units and compare them with the datasheet.

The log is the one bundled with imunoise: 5.5 minutes at 40 Hz, enough for the short
taus (white noise N, and a first look at bias instability B); a real lab adds a log of
a few hours for the long taus.
"""

from importlib import resources

import imunoise
from imunoise import plot

path = resources.files("imunoise") / "data" / "vn100_stationary_5min.txt"
print(path.read_text().splitlines()[0])  # one raw $VNYMR sentence

# %%
# Read the log
# ------------
# :func:`imunoise.read` recognises the format, verifies every checksum and puts the
# samples on the log's uniform time grid. The ``$VNYMR`` sentences carry no time
# stamp, so the sample rate the sensor was set to is given. In a notebook the log
# shows as a table:
log = imunoise.read(path, fs=40.0)
log

# %%
# Every channel per axis (the report's time-series figure):
fig = plot.time_series(log)

# %%
# Sample statistics
# -----------------
# Mean, standard deviation, drift per hour and missing samples per channel
# (:func:`imunoise.describe`):
imunoise.describe(log)

# %%
# The distribution of one axis on its quantization grid, with the fitted normal and
# the goodness-of-fit statistics (:func:`imunoise.distribution`); the report draws one
# panel per axis:
dists = [imunoise.distribution(log.gyro[:, k]) for k in range(3)]
fig = plot.histograms(dists, title="gyro", names=["X", "Y", "Z"], unit="rad/s")
dists[0]

# %%
# Allan deviation
# ---------------
# The overlapping Allan deviation of the three gyro axes, with 68 % confidence
# intervals from the identified noise type (:func:`imunoise.adev`):
result = imunoise.adev(log.gyro, log.fs)
result

# %%
# The noise model
# ---------------
# :func:`imunoise.fit` chooses the terms and fits them; ``model.N``, ``model.B`` …
# are the datasheet values, each with its uncertainty:
model = imunoise.fit(result)
model

# %%
# Behind those values are the fitted terms (``model.terms``, one tuple per axis): the
# IEEE coefficients the fit chose and what it found beyond them — here a tone near
# 18.7 Hz on X and Y, which no sum of power laws follows:
model.terms

# %%
# The Allan deviation with the model, its terms and the data/model panel:
fig = plot.allan(result, model, title="gyro Allan deviation", unit="rad/s")

# %%
# The coefficient table
# ---------------------
# The lab's deliverable, in the units datasheets and lab handouts use:
print(model.table_text("gyro"))

# %%
# Against the datasheet
# ---------------------
# :func:`imunoise.compare` puts the measured values beside the VN-100 datasheet's
# (the accelerometer fitted the same way):
accel = imunoise.fit(imunoise.adev(log.accel, log.fs))
imunoise.compare({"gyro": model, "accel": accel}, "vn100")

# %%
# The same numbers for an estimator: Kalibr's IMU noise file.
print(imunoise.export.kalibr_yaml(model, accel))
