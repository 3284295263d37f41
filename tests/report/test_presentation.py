"""The report as a reader sees it (issue 26): every figure the report draws is checked
in matplotlib (tick labels that do not collide, a unit on every axis, histograms whose
bulk fills the axis and that show no comb of empty and full bins), and the HTML in
headless Chromium (no table wider than its column; skipped without Chromium).

Two reports: the bundled VN-100 capture (events, histograms of real quantized data)
and a simulated still log just long enough for the warm-up and dynamic-ADEV sections.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import warnings
from importlib import resources

import numpy as np
import pytest
from imunoise import plot, report
from imunoise._simulate_log import still_log
from imunoise.plot import _renderer, _tick_labels_overlap
from imunoise.readers.read import read
from matplotlib.patches import StepPatch

BUNDLED = resources.files("imunoise") / "data" / "vn100_stationary_5min.txt"
#: Just over the warm-up section's 1200 s, so it and the dynamic ADEV are drawn.
SIMULATED_HOURS = 0.34
UNIT = re.compile(r"\[[^\]]+\]")


@pytest.fixture(scope="module")
def reports(tmp_path_factory):
    """``{name: (Report, {figure name: Figure})}`` for the two logs; the figures are
    caught as the report saves them."""
    out = {}
    mp = pytest.MonkeyPatch()
    save = plot.save
    try:
        for name in ("bundled", "simulated"):
            figures = {}

            def keep(fig, path, _figures=figures, **kwargs):
                _figures[path.name] = fig
                return save(fig, path, **kwargs)

            mp.setattr(plot, "save", keep)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                log = (read(BUNDLED, fs=40.0) if name == "bundled"
                       else still_log(SIMULATED_HOURS, 40.0, spec="vn100", seed=0))
                rep = report.build(log, None, tmp_path_factory.mktemp(name) / "r",
                                   progress=False, units="datasheet" if name == "bundled"
                                   else None)
            out[name] = (rep, figures)
    finally:
        mp.undo()
    return out


def _all_figures(reports):
    return [(f"{name}/{fig_name}", fig) for name, (_rep, figs) in reports.items()
            for fig_name, fig in figs.items()]


def test_the_report_draws_the_figures_checked_here(reports):
    names = {n.split("/")[1] for n, _f in _all_figures(reports)}
    for wanted in ("adev_gyro", "psd_gyro", "hist_gyro", "hist_mag", "events_gyro", "warmup",
                   "dadev_gyro", "timeseries_attitude", "hist_attitude"):
        assert wanted in names, sorted(names)


def test_no_tick_labels_overlap(reports):
    for name, fig in _all_figures(reports):
        for ax in fig.axes:
            if ax.get_visible():
                assert not _tick_labels_overlap(fig, [ax]), (name, ax.get_title())
        # neighbouring panels of a row: the last label of one and the first of the next
        visible = [ax for ax in fig.axes if ax.get_visible()]
        for a, b in zip(visible, visible[1:], strict=False):
            if abs(a.get_position().y0 - b.get_position().y0) < 1e-6:
                assert not _tick_labels_overlap(fig, [a, b]), (name, a.get_title(), b.get_title())


def _shows_ticks(axis, renderer) -> bool:
    return any(t.label1.get_visible() and t.label1.get_text() for t in axis._update_ticks())


def _label_of_shared(ax, which: str) -> str:
    """The axis label of ``ax`` or of an axes it shares that axis with."""
    group = ax.get_shared_x_axes() if which == "x" else ax.get_shared_y_axes()
    labels = [getattr(a, f"get_{which}label")() for a in group.get_siblings(ax)]
    return next((lab for lab in labels if lab), "")


def test_every_axis_is_labelled_with_a_unit(reports):
    for name, fig in _all_figures(reports):
        renderer = _renderer(fig)
        fig.draw(renderer)  # tick labels as saved
        for ax in fig.axes:
            if not ax.get_visible():
                continue
            for which, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
                if not _shows_ticks(axis, renderer):
                    continue
                label = _label_of_shared(ax, which)
                assert UNIT.search(label), (name, ax.get_title(), which, label)


def _histogram_panels(reports):
    for name, fig in _all_figures(reports):
        if "/hist_" not in name:
            continue
        for ax in fig.axes:
            bars = [p for p in ax.patches if isinstance(p, StepPatch)]
            if bars:
                data = bars[0].get_data()
                yield name, ax, np.asarray(data.values, float), np.asarray(data.edges, float)


def test_every_histogram_bulk_fills_its_axis(reports):
    panels = list(_histogram_panels(reports))
    assert len(panels) >= 12
    for name, ax, values, edges in panels:
        if np.count_nonzero(values) < 2:  # a constant channel: no spread to show
            continue
        mass = np.cumsum(values * np.diff(edges))
        mass /= mass[-1]
        lo = np.interp(0.005, mass, edges[1:])
        hi = np.interp(0.995, mass, edges[1:])
        left, right = ax.get_xlim()
        assert (hi - lo) / (right - left) >= 0.5, (name, ax.get_title(), lo, hi, left, right)


def _comb(values: np.ndarray) -> bool:
    """Bins alternating empty and full over at least 5 bins: three dips (below half of
    both neighbours) two bins apart, in the histogram's core (neighbours above a tenth
    of the highest bin)."""
    v = values
    core = v > 0.1 * v.max()
    dip = np.zeros(len(v), dtype=bool)
    dip[1:-1] = (v[1:-1] < 0.5 * np.minimum(v[:-2], v[2:])) & core[:-2] & core[2:]
    return bool(np.any(dip[:-4] & dip[2:-2] & dip[4:]))


def test_comb_check_sees_a_comb():
    assert _comb(np.array([1, 10, 1, 10, 1, 10, 1, 10, 1], float) * 1.0)
    assert not _comb(np.array([1, 3, 6, 9, 10, 9, 6, 3, 1], float))


def test_no_histogram_is_a_comb(reports):
    for name, ax, values, _edges in _histogram_panels(reports):
        assert not _comb(values), (name, ax.get_title(), values.tolist())


# -- in the browser -------------------------------------------------------------------

#: Width of the window the HTML is laid out in (a laptop's).
WINDOW = (1366, 768)
_MEASURE = """<script>
window.addEventListener('load', () => {
  document.querySelectorAll('details').forEach(d => { d.open = true; });
  const out = [];
  document.querySelectorAll('div.tw').forEach(tw => {
    const t = tw.querySelector('table');
    out.push([t.caption ? t.caption.textContent : '', t.scrollWidth, tw.clientWidth]);
  });
  const pre = document.createElement('pre');
  pre.id = 'measured';
  pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
});
</script>"""


def _chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    pytest.skip("no Chromium on PATH (apt-get install chromium)")


def _table_widths(exe: str, html_path) -> list[tuple[str, int, int]]:
    """(caption, table width, column width) of every table, in px, laid out by Chromium."""
    page = html_path.with_name("measure.html")
    page.write_text(html_path.read_text(encoding="utf-8").replace(
        "</body>", _MEASURE + "</body>"), encoding="utf-8")
    dom = subprocess.run(
        [exe, "--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run",
         f"--window-size={WINDOW[0]},{WINDOW[1]}", "--dump-dom", page.as_uri()],
        check=True, capture_output=True, text=True, timeout=120).stdout
    found = re.search(r'<pre id="measured">(.*?)</pre>', dom, re.S)
    assert found, dom[-2000:]
    text = found.group(1).replace("&quot;", '"').replace("&amp;", "&")
    return [tuple(row) for row in json.loads(text)]


def test_no_table_is_wider_than_its_column_in_chromium(reports):
    exe = _chromium()
    for name, (rep, _figs) in reports.items():
        widths = _table_widths(exe, rep.html)
        assert len(widths) >= 8, widths
        wide = [w for w in widths if w[1] > w[2]]
        assert not wide, (name, wide)
