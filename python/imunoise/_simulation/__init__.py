"""Simulated data: noise of given coefficients (simulate), noise like a measured sensor's
(like: ``imunoise.simulate(like=...)``) and whole logs in a sensor's format (log:
``imunoise.simulate_log``). Private: the public names are the facade's functions."""
