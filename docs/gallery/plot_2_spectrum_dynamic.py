"""
Spectrum and dynamic Allan deviation
====================================

Two more views of the same noise, as the report draws them: the power spectral density
with the noise density N read off and the fitted model over it, and the Allan deviation
of a sliding window, which shows whether the noise stays the same along the record.

The record is simulated (:func:`imunoise.simulate`): 40 minutes at 40 Hz of white
noise, bias instability and rate random walk, with the white noise doubled over ten
minutes in the middle — a change the dynamic Allan deviation finds.
"""

import imunoise
from imunoise import plot

fs = 40.0
n = int(40 * 60 * fs)
x = imunoise.simulate(n, fs, N=6e-5, B=2e-5, K=2e-6, channels=3, seed=0)
louder = slice(n // 2, n // 2 + int(600 * fs))
x[louder] += imunoise.simulate(int(600 * fs), fs, N=1e-4, channels=3, seed=1)

# %%
# Power spectral density
# ----------------------
# A one-sided Welch estimate with χ² bands; ``N`` is √(white level / 2), the IEEE
# (two-sided) density that :func:`imunoise.fit` reports too:
spectrum = imunoise.psd(x, fs)
model = imunoise.fit(imunoise.adev(x, fs))
spectrum

# %%
fig = plot.spectrum(spectrum, model, unit="rad/s", title="gyro PSD")

# %%
# Dynamic Allan deviation
# -----------------------
# The Allan deviation of a 5-minute window every minute, and where the noise departs
# from the record's own:
dyn = imunoise.dynamic_adev(x, fs, window=300.0, step=60.0)
dyn

# %%
fig = plot.dynamic(dyn, title="gyro dynamic Allan deviation")

# %%
# The departures, each to within one step: the louder ten minutes, found on every axis
# with the ratio of its deviation to the record's.
dyn.stationarity
