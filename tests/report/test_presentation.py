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
from imunoise._simulation.log import still_log
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
        assert not _unlabelled_axes(fig), (name, _unlabelled_axes(fig))


def _unlabelled_axes(fig) -> list[tuple[str, str, str]]:
    """(panel title, x or y, label) of every axis that shows tick labels but no unit."""
    renderer = _renderer(fig)
    fig.draw(renderer)
    out = []
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        for which, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            if _shows_ticks(axis, renderer):
                label = _label_of_shared(ax, which)
                if not UNIT.search(label):
                    out.append((ax.get_title(), which, label))
    return out


def test_figures_of_arrays_without_a_unit_still_label_every_axis():
    """``r.plot(model)`` and the other figures of arrays: the input's unit, said so."""
    import imunoise

    fs = 40.0
    y = imunoise.simulate(int(fs * 1500), fs, N=1e-3, K=1e-5, channels=2, seed=3)
    r = imunoise.adev(y, fs)
    figures = [r.plot(imunoise.fit(r, warn_coverage=False)), r.plot(),
               plot.spectrum(imunoise.psd(y, fs)),
               plot.dynamic(imunoise.dynamic_adev(y, fs)),
               plot.warmup(imunoise.warmup(y, fs)),
               plot.histograms([imunoise.distribution(y[:, 0])]),
               plot.time_series(y, fs)]
    for fig in figures:
        assert not _unlabelled_axes(fig), _unlabelled_axes(fig)


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


# -- tables: the lab table first, one unit per quantity ----------------------------------


def _md_tables(md: str) -> dict[str, list[list[str]]]:
    """Every Markdown table by its caption (``*caption*`` or a collapsed table's
    ``<summary>``), rows with the header first."""
    out, caption, rows = {}, None, []
    for line in [*md.splitlines(), ""]:
        if line.startswith("|"):
            if not set(line) <= set("|-"):
                rows.append([c.strip() for c in line.strip("|").split("|")])
            continue
        if rows:
            out[caption] = rows
            rows = []
        if line.startswith("*") and line.endswith("*") and len(line) > 2:
            caption = line.strip("*")
        elif line.startswith("<summary>"):
            caption = re.sub(r" \(\d+ rows\)</summary>$", "", line[len("<summary>"):])
    return out


def test_lab_table_is_the_first_table_of_the_noise_section(reports):
    rep, _figs = reports["bundled"]
    md = rep.markdown.read_text(encoding="utf-8")
    section = md.split(". Noise coefficients\n")[1].split("\n## ")[0]
    first = next(line for line in section.splitlines() if line.startswith("*"))
    assert first.startswith("*Lab table: N, B and K per axis beside the datasheet (vn100)")
    # and after each sensor's sentences, how long to record for N, B, K (imunoise plan)
    plans = [line for line in section.splitlines() if line.startswith("Plan (")]
    assert [p.split(")")[0] for p in plans] == ["Plan (gyro", "Plan (accel"]
    assert all("needs N" in p and "this record" in p for p in plans)
    rows = _md_tables(section)[first.strip("*")]
    assert rows[0] == ["sensor", "quantity", "unit", "X", "Y", "Z", "datasheet", "as printed"]
    by = {(r[0], r[1]): r for r in rows[1:]}
    # datasheet units (--units datasheet): the VN-100's own, 0.0035 °/s/√Hz, 0.14 mg/√Hz
    # and < 0.04 mg; the accelerometer's K in the same family (mg/√s), never m/s²/√s
    gyro_n = by[("gyro", "angle random walk (N)")]
    assert gyro_n[2] == "°/s/√Hz" and float(gyro_n[6]) == pytest.approx(0.0035)
    accel_n = by[("accel", "velocity random walk (N)")]
    assert accel_n[2] == "mg/√Hz" and float(accel_n[6]) == pytest.approx(0.14)
    assert accel_n[7] == "0.14 mg/√Hz typ."
    accel_b = by[("accel", "bias instability (B)")]
    assert accel_b[2] == "mg" and float(accel_b[6]) == pytest.approx(0.04)
    assert by[("accel", "rate random walk (K)")][2] == "mg/√s"
    assert [r[1] for r in rows[1:4]] == ["angle random walk (N)", "bias instability (B)",
                                        "rate random walk (K)"]


def _units_by_quantity(md: str) -> dict[tuple[str, str], set[str]]:
    """(sensor, term) -> the units the report's tables write it in."""
    tables = _md_tables(md)
    seen: dict[tuple[str, str], set[str]] = {}
    for caption, rows in tables.items():
        if caption is None:
            continue
        header = rows[0]
        if caption.startswith("Lab table") or caption.startswith("Measured vs datasheet"):
            q, u = header.index("quantity"), header.index("unit")
            for r in rows[1:]:
                term = re.search(r"\((\w)\)$", r[q]).group(1)
                seen.setdefault((r[0], term), set()).add(r[u])
        elif caption.endswith("noise coefficients per axis"):
            sensor = caption.split()[0]
            for r in rows[1:]:
                seen.setdefault((sensor, r[1]), set()).add(r[2])
        elif "noise density from the spectrum" in caption:
            sensor = caption.split(":")[0]
            for h in header:
                if h.startswith("N "):
                    seen.setdefault((sensor, "N"), set()).add(h[h.index("[") + 1:-1])
    return seen


def test_one_unit_per_quantity_across_the_tables(reports):
    for name, (rep, _figs) in reports.items():
        seen = _units_by_quantity(rep.markdown.read_text(encoding="utf-8"))
        assert ("accel", "B") in seen and ("gyro", "N") in seen, seen
        for key, units in seen.items():
            assert len(units) == 1, (name, key, units)
    bundled = _units_by_quantity(reports["bundled"][0].markdown.read_text(encoding="utf-8"))
    simulated = _units_by_quantity(reports["simulated"][0].markdown.read_text(encoding="utf-8"))
    assert bundled[("gyro", "N")] == {"°/s/√Hz"} and bundled[("accel", "B")] == {"mg"}
    assert simulated[("gyro", "N")] == {"°/√h"} and simulated[("accel", "N")] == {"µg/√Hz"}
    # one family per accelerometer: never mg beside µg, nor an SI K beside them
    for seen in (bundled, simulated):
        accel = {u for (sensor, term), units in seen.items() if sensor == "accel"
                 and term in "NBK" for u in units}
        assert not ({u for u in accel if u.startswith("mg")}
                    and {u for u in accel if u.startswith("µg")}), accel
        assert not any(u.startswith("m/s") for u in accel), accel


def test_lab_table_text_and_its_units():
    import imunoise

    y = imunoise.simulate(200_000, 40.0, N=1e-4, B=2e-5, K=1e-6, channels=3, seed=2)
    model = imunoise.fit(imunoise.adev(y, 40.0, taus=10), warn_coverage=False)
    text = model.table_text("lab", sensor="gyro", spec="vn100", units="datasheet")
    lines = text.splitlines()
    assert lines[0].split()[-3:] == ["datasheet", "as", "printed"]
    n_line = next(line for line in lines if line.startswith("N "))
    assert "°/s/√Hz" in n_line and "0.0035 °/s/√Hz typ." in n_line
    assert len([line for line in lines[2:] if line.strip()]) == 3  # N, B, K only
    rows = {r["term"]: r for r in model.lab_table("gyro", spec="vn100")}
    # the datasheet's 10 °/h, in the default unit of B (°/h), beside the measured values
    assert rows["B"]["spec"] == pytest.approx(10.0) and rows["B"]["spec_text"] == "< 10 °/h"
    assert rows["K"]["spec_text"] == "—" and np.isnan(rows["K"]["spec"])
    assert rows["N"]["spec"] == pytest.approx(0.0035 * 60)  # °/s/√Hz -> °/√h
    with pytest.raises(ValueError, match="sensor once"):
        model.table_text("accel", sensor="gyro")


def test_cli_report_units_datasheet_is_parsed_beside_the_layout_units():
    from imunoise.cli import _TABLE_UNITS, _build_parser

    args = _build_parser().parse_args(["report", "x.txt", "--units", "datasheet",
                                       "--units", "gyro=deg/s"])
    assert _TABLE_UNITS in args.units and ("gyro", "deg/s") in args.units


def test_columns_of_words_are_left_aligned_and_long_tables_collapse():
    from imunoise.report.document import Doc

    doc = Doc()
    doc.table(["channel", "value", "verdict", "Z"],
              [["gyro X", "(1.2 ± 0.1)e-3", "pass", "not resolved"],
               ["gyro Y", "< 10", "fail (2× typical)", "—"]], caption="t")
    doc.table(["τ [s]", "σ"], [["0.1", "2"]] * 40, caption="long", collapsed=True)
    html = doc.html("x")
    assert '<td class="l">pass</td>' in html and '<td>(1.2 ± 0.1)e-3</td>' in html
    assert '<td>not resolved</td>' in html  # a column without a word or a number: as is
    assert "<details><summary>long (40 rows)</summary>" in html


# --- a report a student reads without help -------------------------------------------


def test_figures_have_plain_tick_labels(reports):
    """No matplotlib offset or power of ten in an axis corner ("−10" beside the ticks of
    accel Z): a shared offset is in the axis label, in the axis's unit."""
    for name, fig in _all_figures(reports):
        fig.canvas.draw()
        for ax in fig.axes:
            for axis in (ax.xaxis, ax.yaxis):
                assert axis.get_offset_text().get_text() == "", (name, axis.get_label_text())
    _rep, figs = reports["bundled"]
    # the VN-100 capture's accel Z sits near −9.9 m/s²: its histogram counts from there
    z = figs["hist_accel"].axes[2].get_xlabel()
    assert re.fullmatch(r"Z \+ [\d.]+ \[m/s²\]", z), z


def test_histogram_titles_are_rounded_like_the_tables(reports):
    for name, fig in _all_figures(reports):
        if "hist_" not in name:
            continue
        for ax in fig.axes:
            title = ax.get_title()
            # a mantissa from 1 to 10 ("6e-6", never "0.6e-5"); no "67.20"-style padding
            assert not re.search(r"(?<![\d.])-?0\.\d+e-?\d", title), (name, title)
            assert "μ = " in title and "σ = " in title


def test_off_scale_counts_are_explained(reports):
    rep, figs = reports["bundled"]
    md = rep.markdown.read_text(encoding="utf-8")
    counted = [n for n, fig in figs.items() if n.startswith("hist_") and any(
        t.get_text().startswith("←") or t.get_text().endswith("→")
        for ax in fig.axes for t in ax.texts)]
    assert counted, "the bundled capture has samples beyond a histogram's range"
    for n in counted:
        caption = re.search(rf"!\[([^\]]*)\]\(figures/{n}\.png\)", md).group(1)
        assert "upper corners" in caption and "beyond the plotted range" in caption, caption


def test_contents_at_the_top(reports):
    rep, _figs = reports["simulated"]
    md = rep.markdown.read_text(encoding="utf-8")
    html = rep.html.read_text(encoding="utf-8")
    headings = re.findall(r"^## (.+)$", md, flags=re.M)
    assert md.index("**Contents**") < md.index("## 1.")
    for h in headings:
        assert f"- [{h}](#" in md
    toc = html[html.index('<nav class="toc">'):html.index("</nav>")]
    assert html.index('<nav class="toc">') < html.index("<h2")
    anchors = re.findall(r'<h2 id="([^"]+)">', html)
    assert re.findall(r'href="#([^"]+)"', toc) == anchors and len(anchors) == len(headings)


def test_one_log_is_not_called_short_or_long(reports):
    for name, (rep, figs) in reports.items():
        md = rep.markdown.read_text(encoding="utf-8")
        assert "short log" not in md.lower() and "long log" not in md.lower(), name
        for fig_name, fig in figs.items():
            titles = [fig._suptitle.get_text() if fig._suptitle else ""]
            assert not any("short log" in t or "long log" in t for t in titles), fig_name


def test_one_unit_spelling_and_links_to_the_documentation_site(reports):
    from imunoise.report.formatting import DOCS_URL

    for name, (rep, figs) in reports.items():
        for text in (rep.markdown.read_text(encoding="utf-8"),
                     rep.html.read_text(encoding="utf-8")):
            assert "m/s^2" not in text and "docs/" not in text, name
            assert DOCS_URL in text
        for fig_name, fig in figs.items():
            labels = [a.get_label_text() for ax in fig.axes for a in (ax.xaxis, ax.yaxis)]
            assert not any("^2" in x for x in labels), (fig_name, labels)


def test_comparison_says_which_uncertainty_its_verdicts_use(reports):
    rep, _figs = reports["simulated"]
    md = rep.markdown.read_text(encoding="utf-8")
    tables = _md_tables(md)
    lab = next(rows for c, rows in tables.items() if c and c.startswith("Lab table"))
    cmp = next(rows for c, rows in tables.items() if c and c.startswith("Measured vs"))
    lab_b = {r[0]: r for r in lab[1:] if r[1].endswith("(B)")}
    for r in cmp[1:]:
        if not r[1].endswith("(B)") or " ± " not in r[4]:
            continue
        fit_std = float(lab_b[r[0]][3 + "XYZ".index(r[2])].split(" ± ")[1])
        # the record's own uncertainty of B is never below the fit's
        assert float(r[4].split(" ± ")[1]) >= fit_std * 0.99, (r, fit_std)
    assert "the larger of the fit's" in md
    plans = [line for line in md.splitlines() if line.startswith("Plan (")]
    assert plans and all("95 % intervals of a read-off" in p for p in plans)


def test_an_assumed_sample_rate_is_said_in_the_report(tmp_path):
    """A log without timestamps read without ``--fs``: the report says, at its top and
    in the command line's words, that 40 Hz was assumed."""
    lines = BUNDLED.read_text(encoding="utf-8").splitlines(keepends=True)
    path = tmp_path / "vn.txt"
    path.write_text("".join(lines[:4000]), encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = report.build(path, None, tmp_path / "r", progress=False, spec=None)
        given = report.build(path, None, tmp_path / "given", progress=False, spec=None,
                             fs=40.0)
    md = rep.markdown.read_text(encoding="utf-8")
    note = md[:md.index("## 1.")]
    assert "**Sample rate assumed**" in note and "40 Hz" in note and "`--fs" in note
    assert "Sample rate assumed" in rep.html.read_text(encoding="utf-8")
    assert "Sample rate assumed" not in given.markdown.read_text(encoding="utf-8")
