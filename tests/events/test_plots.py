"""plot.events, plot.warmup, plot.thermal, plot.compensation: what they draw."""

import imunoise
import numpy as np
import pytest
from imunoise import plot

FS = 10.0


def test_events_shaded_on_every_panel_where_they_are(tmp_path):
    rng = np.random.default_rng(0)
    x = rng.standard_normal((20_000, 3))
    x[5000:5030, 1] += 8 * rng.standard_normal(30)
    found = imunoise.events(x, FS)
    fig = plot.events(x, found, title="t")
    panels = [ax for ax in fig.axes if ax.get_visible()]
    assert len(panels) == 3
    for ax in panels:
        (span,) = ax.patches[-1:]  # the last patch drawn is the event's
        # 2000 s of record: the time axis is in minutes
        assert span.get_x() * 60 == pytest.approx(found.start[0])
        assert (span.get_x() + span.get_width()) * 60 >= found.end[0] - 1e-9
    assert any(t.get_text().endswith("σ") for t in panels[0].texts)
    written = plot.save(fig, tmp_path / "events")
    assert all(p.stat().st_size > 0 for p in written)


def test_warmup_plot_marks_the_settle_point_and_temperature():
    t = np.arange(36_000) / FS
    rng = np.random.default_rng(1)
    x = 1e-3 * rng.standard_normal(len(t)) + 2e-3 * np.exp(-t / 300)
    found = imunoise.warmup(x, FS, temperature=40 - 5 * np.exp(-t / 400), tolerance=1e-5)
    fig = plot.warmup(found)
    value_ax, temp_ax = fig.axes
    assert temp_ax.get_ylabel() == "temperature [°C]"
    settle_lines = [ln for ln in value_ax.lines if ln.get_linestyle() == ":"]
    assert settle_lines and settle_lines[0].get_xdata()[0] * 60 == found.settle
    assert "settled at" in fig._suptitle.get_text()


def test_thermal_and_compensation_plots():
    n = 36_000
    temp = 30 + 10 * (1 - np.exp(-np.arange(n) / FS / 900))
    rng = np.random.default_rng(2)
    x = 1e-4 * rng.standard_normal((n, 3)) + 2e-5 * (temp - 35)[:, None]
    fit = imunoise.thermal(x, temp, FS, sensor="gyro")
    fig = plot.thermal(fit)
    assert len([ax for ax in fig.axes if ax.get_visible()]) == 3
    assert "°/h/°C" in fig.axes[0].get_legend().get_texts()[0].get_text()
    before, after = imunoise.adev(x, FS), imunoise.adev(fit.compensated, FS)
    fig = plot.compensation(before, after, unit="rad/s")
    (ax,) = fig.axes
    assert len(ax.lines) == 6
    # compensation removes the thermal drift: the long-tau deviation drops
    assert np.all(after.dev[-1] < before.dev[-1])
