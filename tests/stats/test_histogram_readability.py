"""Histograms that read well on every channel of real logs (issue #26): the bulk of the
data fills the axis, no comb of empty bins, tick labels that do not collide.

The checks measure what a reader sees, independently of how ``distribution`` builds
its edges: the bins holding the central 99 % against the whole x axis, runs of bins
alternating empty/full, and the tick labels' extents on matplotlib's renderer.
"""

from importlib import resources

import imunoise
import numpy as np
import pytest
from helpers.data import DATA, shared_file
from imunoise import plot
from imunoise.stats import unwrap_about_circular_mean

#: The bins of the central 99 % span at least this share of the x axis.
MIN_BULK_SHARE = 0.5
#: No run of this many bins of the bulk alternating empty/full.
COMB_RUN = 5


def bulk_bins(d, x) -> slice:
    """The bins holding the central 99 % of ``x``."""
    lo, hi = np.quantile(x, [0.005, 0.995])
    i = int(np.clip(np.searchsorted(d.edges, lo, side="right") - 1, 0, len(d.counts) - 1))
    j = int(np.clip(np.searchsorted(d.edges, hi, side="right") - 1, 0, len(d.counts) - 1))
    return slice(i, j + 1)


def bulk_share(d, x) -> float:
    """Width of the bins holding the central 99 % of ``x`` over the histogram's width."""
    bulk = bulk_bins(d, x)
    return (d.edges[bulk.stop] - d.edges[bulk.start]) / (d.edges[-1] - d.edges[0])


def longest_alternation(counts) -> int:
    """Longest run of bins whose emptiness flips from each bin to the next."""
    empty = np.asarray(counts) == 0
    best = run = 1
    for a, b in zip(empty[:-1], empty[1:], strict=True):
        run = run + 1 if a != b else 1
        best = max(best, run)
    return best


def overlapping_tick_labels(fig) -> list[tuple[str, str]]:
    """Pairs of drawn tick labels (x or y, any panel) whose extents intersect."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    boxes = []
    for ax in fig.axes:
        for axis, lim in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
            lo, hi = min(lim), max(lim)
            for loc, label in zip(axis.get_majorticklocs(), axis.get_majorticklabels(),
                                  strict=False):
                if lo <= loc <= hi and label.get_visible() and label.get_text():
                    boxes.append((label.get_text(), label.get_window_extent(renderer)))
    return [(a[0], b[0]) for i, a in enumerate(boxes) for b in boxes[i + 1:]
            if a[1].overlaps(b[1])]


def check_channel(name: str, x: np.ndarray) -> list[str]:
    x = x[np.isfinite(x)]
    d = imunoise.distribution(x)
    problems = []
    share = bulk_share(d, x)
    if share < MIN_BULK_SHARE:
        problems.append(f"{name}: bulk spans {share:.0%} of the axis")
    # in the bulk: the far tails hold a sample every few bins by chance, not a comb
    run = longest_alternation(d.counts[bulk_bins(d, x)])
    if run >= COMB_RUN:
        problems.append(f"{name}: {run} bins alternate empty/full")
    assert d.counts.sum() + d.off_scale == len(x)
    return problems


def check_log(log) -> list[str]:
    problems = []
    for sensor in ("gyro", "accel", "mag"):
        y = getattr(log, sensor)
        if y is None:
            continue
        for j in range(y.shape[1]):
            problems += check_channel(f"{sensor} {'XYZ'[j]}", y[:, j])
        fig = plot.histograms([imunoise.distribution(c[np.isfinite(c)]) for c in y.T],
                              unit=sensor)
        problems += [f"{sensor}: tick labels {pair} overlap"
                     for pair in overlapping_tick_labels(fig)]
    if log.ypr is not None:
        angles = log.ypr.copy()
        angles[:, 0] = unwrap_about_circular_mean(angles[:, 0])
        for j, name in enumerate(("yaw", "pitch", "roll")):
            problems += check_channel(name, angles[:, j])
        fig = plot.histograms([imunoise.distribution(c[np.isfinite(c)]) for c in angles.T],
                              unit="deg", names=["yaw", "pitch", "roll"])
        problems += [f"attitude: tick labels {pair} overlap"
                     for pair in overlapping_tick_labels(fig)]
    return problems


def test_bundled_still_log_histograms_read_well():
    path = resources.files("imunoise") / "data" / "vn100_stationary_5min.txt"
    assert check_log(imunoise.read(str(path), fs=40)) == []


def test_moving_rugged_log_histograms_read_well():
    assert check_log(imunoise.read(str(DATA / "rugged_0513test.txt"), fs=40)) == []


def test_live_capture_histograms_read_well():
    """The 12.6-minute VN-100 capture of the issue: 6 of 12 channels failed (gyro bulk
    12–18 % of the axis, accel Z 22 %, mag X 38 %, mag Y a comb of empty bins)."""
    log = imunoise.read(str(shared_file("data/vn100-ascii/live_capture.txt")), fs=40)
    assert check_log(log) == []


def _quantized(rng, n, sigma, step, offset=0.0):
    return np.round((offset + rng.normal(0.0, sigma, n)) / step) * step


@pytest.mark.parametrize("sigma_steps", [0.6, 1.5, 4.0, 40.0])
def test_simulated_quantized_histograms_read_well(sigma_steps):
    rng = np.random.default_rng(int(sigma_steps * 10))
    step = 1e-3
    x = _quantized(rng, 30_000, sigma_steps * step, step, offset=-134.2)
    assert check_channel("quantized", x) == []
    fig = plot.histograms(imunoise.distribution(x), unit="deg")
    assert overlapping_tick_labels(fig) == []


def test_vibration_spikes_stay_off_scale_and_are_counted():
    """A still gyro with a few vibration bursts 50 σ out: the axis follows the bulk and
    the spikes are counted, on the result and on the panel."""
    rng = np.random.default_rng(3)
    x = _quantized(rng, 30_000, 1e-3, 1e-6)
    spikes = rng.choice(len(x), 40, replace=False)
    x[spikes[:25]] = -0.05
    x[spikes[25:]] = 0.05
    d = imunoise.distribution(x)
    assert (d.off_scale_below, d.off_scale_above) == (25, 15)
    assert d.counts.sum() == len(x) - 40
    assert bulk_share(d, x) >= MIN_BULK_SHARE
    # the density stays comparable to the fitted pdf: it integrates to the share on scale
    np.testing.assert_allclose(np.sum(d.density() * np.diff(d.edges)), 1 - 40 / len(x))
    full = imunoise.distribution(x, extent="all")
    assert full.off_scale == 0 and full.edges[0] <= -0.05 and full.edges[-1] >= 0.05
    fig = plot.histograms(d)
    texts = [t.get_text() for t in fig.axes[0].texts]
    assert "← 25" in texts and "15 →" in texts
    with pytest.raises(ValueError, match="extent"):
        imunoise.distribution(x, extent="most")


def test_sparse_levels_with_rare_values_between():
    """Mag-Y-like data: sensor levels ~1e-3 apart, each printed as a cluster of two or
    three adjacent 1e-4 values, and now and then a rare value between the clusters
    (the live capture's mag Y): bins are a level wide, not a comb of 1e-4 bins."""
    rng = np.random.default_rng(11)
    level = np.round(rng.normal(0.0, 3.3, 30_000))
    x = 0.16 + level * 0.99e-3 + rng.choice([-1e-4, 0.0, 0.0, 0.0, 1e-4], len(level))
    rare = rng.choice(len(x), 12, replace=False)
    x[rare] += 4e-4
    x = np.round(x, 4)
    d = imunoise.distribution(x)
    assert d.level_spacing == pytest.approx(0.99e-3, rel=0.05)
    assert check_channel("sparse", x) == []
