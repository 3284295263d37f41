"""The before/after Allan figure labels its log axes as plot.allan does: decades only,
never a minor tick's "6 × 10⁻⁴" beside the decade labels."""

from __future__ import annotations

import imunoise
import numpy as np
from imunoise import plot


def test_compensation_labels_decades_only():
    taus = np.geomspace(0.1, 10.0, 9)  # white noise over two decades of τ: one of σ
    before = imunoise.adev(imunoise.simulate(40_000, 10.0, N=1e-3, channels=2, seed=4), 10.0,
                           taus=taus)
    after = imunoise.adev(imunoise.simulate(40_000, 10.0, N=8e-4, channels=2, seed=5), 10.0,
                          taus=taus)
    fig = plot.compensation(before, after, unit="rad/s")
    (ax,) = fig.axes
    low, high = ax.get_ylim()
    assert high / low < 100  # under two decades: where matplotlib labels minor ticks
    fig.canvas.draw()
    minor = [t.get_text() for t in ax.yaxis.get_minorticklabels() if t.get_text()]
    assert minor == [], minor
    major = [t.get_text() for t in ax.yaxis.get_majorticklabels() if t.get_text()]
    assert major and all("10^{" in t for t in major), major


def test_compensation_within_one_decade_keeps_its_labels():
    taus = np.geomspace(0.1, 0.5, 5)  # σ from about 3e-3 to 1.4e-3: no decade inside
    before = imunoise.adev(imunoise.simulate(40_000, 10.0, N=1e-3, seed=6), 10.0, taus=taus)
    after = imunoise.adev(imunoise.simulate(40_000, 10.0, N=9e-4, seed=7), 10.0, taus=taus)
    fig = plot.compensation(before, after)
    (ax,) = fig.axes
    fig.canvas.draw()
    labels = [t.get_text() for t in [*ax.yaxis.get_majorticklabels(),
                                     *ax.yaxis.get_minorticklabels()] if t.get_text()]
    assert labels, "an axis without a decade must keep its minor labels"
