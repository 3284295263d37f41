"""The report directory: files, tables parsed back and compared with the API, embedded images."""

import json
import re
from pathlib import Path

import imunoise
import numpy as np
import pytest
from imunoise import datasheet, display, report
from imunoise.stats import describe, distribution

FS = 40.0


def _vn_like(n, seed, drift=0.0):
    """Still-IMU arrays quantized like VN-100 text output (gyro 1e-6, accel 1e-3)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    gyro = rng.normal(0, 1e-3, (n, 3)) + np.cumsum(rng.normal(0, 2e-6, (n, 3)), axis=0)
    accel = rng.normal(0, 0.01, (n, 3)) + np.array([0.0, 0.0, -9.81])
    accel[:, 0] += drift * t / 3600
    mag = rng.normal(0, 2e-4, (n, 3)) + np.array([0.25, 0.05, -0.33])
    return imunoise.ImuLog.from_arrays(
        FS,
        gyro=np.round(gyro, 6),
        accel=np.round(accel, 3),
        mag=np.round(mag, 4),
        source="<test arrays>",
    )


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    out = tmp_path_factory.mktemp("report")
    short = _vn_like(4000, 1, drift=0.3)
    long = _vn_like(40000, 2)
    rep = report.build(short, long, out, progress=False)
    return rep, short, long


def _md_table(md: str, caption: str) -> list[list[str]]:
    """Rows (header first) of the Markdown table that follows ``*caption*``."""
    lines = md.splitlines()
    # a long table is collapsed: <summary>caption (N rows)</summary>
    i = next(k for k, line in enumerate(lines) if line == f"*{caption}*"
             or line.startswith(f"<summary>{caption} ("))
    rows = []
    for line in lines[i + 2:]:
        if not line.startswith("|"):
            break
        if set(line) <= set("|-"):
            continue
        rows.append([c.strip() for c in line.strip("|").split("|")])
    return rows


def test_files_exist(built):
    rep, _, _ = built
    out = rep.out_dir
    assert (out / "report.html").stat().st_size > 10_000
    assert (out / "report.md").is_file()
    pngs = sorted((out / "figures").glob("*.png"))
    svgs = sorted((out / "figures").glob("*.svg"))
    # time series (3 short + 3 long), histograms (3), Allan (2), PSD (2), dynamic ADEV (2)
    assert len(pngs) == 15 and len(svgs) == 15
    for p in pngs:
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    for s in svgs:
        assert b"<svg" in s.read_bytes()[:2000]


def _value_std(text):
    """``"1.23 ± 0.04"`` or ``"(1.23 ± 0.04)e-3"`` as two floats."""
    m = re.fullmatch(r"\(?(\S+) ± ([^)\s]+)\)?(?:e(-?\d+))?", text)
    scale = 10.0 ** int(m.group(3) or 0)
    return float(m.group(1)) * scale, float(m.group(2)) * scale


def test_statistics_table_matches_describe(built):
    rep, short, _ = built
    md = rep.markdown.read_text()
    rows = _md_table(md, "Sample statistics (short log)")
    d = describe(short)
    assert [r[0] for r in rows[1:]] == list(d.names)
    for r, name in zip(rows[1:], d.names, strict=True):
        i = d.names.index(name)
        got = [float(v) for v in r[2:8]]
        want = [d.mean[i], d.std[i], d.var[i], d.min[i], d.max[i], d.drift_per_hour[i]]
        np.testing.assert_allclose(got, want, rtol=5e-6, atol=1e-300)
    # the injected drift shows up in the report
    assert abs(float(rows[4][7]) - 0.3) < 0.15


def test_distribution_table_matches_api(built):
    rep, short, _ = built
    md = rep.markdown.read_text()
    rows = _md_table(md, "Distribution fits (short log)")
    assert rows[0][:4] == ["channel", "unit", "μ", "σ"]
    by_name = {r[0]: r for r in rows[1:]}
    bins = _md_table(md, "Histogram bins (short log): the sensor's quantization step and the "
                         "spacing of the levels it uses")
    assert bins[0] == ["channel", "unit", "quantization step", "level spacing", "bins"]
    bins_of = {r[0]: r for r in bins[1:]}
    for sensor, step in (("gyro", 1e-6), ("accel", 1e-3), ("mag", 1e-4)):
        for j, axis in enumerate("XYZ"):
            r, b = by_name[f"{sensor} {axis}"], bins_of[f"{sensor} {axis}"]
            d = distribution(getattr(short, sensor)[:, j])
            assert float(b[2]) == pytest.approx(step, rel=1e-4)
            assert float(b[3]) == pytest.approx(d.level_spacing, rel=1e-5)
            assert int(b[4]) == len(d.counts)
            # μ and σ rounded to their uncertainties (GUM), the statistics to 4 digits
            assert r[2] == display.format_value(d.mu, d.mu_std)
            assert r[3] == display.format_value(d.sigma, d.sigma_std)
            got = [float(v) for v in (r[4], r[6], r[7], r[8])]
            want = [d.ks_statistic, d.ad_statistic, d.skewness, d.excess_kurtosis]
            np.testing.assert_allclose(got, want, rtol=5e-4)


def test_allan_table_matches_adev(built):
    rep, _, long = built
    md = rep.markdown.read_text()
    for sensor in ("gyro", "accel"):
        rows = _md_table(md, f"Allan deviation of {sensor}: every τ")
        r = imunoise.adev(getattr(long, sensor), long.fs, taus=report.TAUS_PER_DECADE)
        assert len(rows) - 1 == len(r.taus)
        taus = [float(x[0]) for x in rows[1:]]
        np.testing.assert_allclose(taus, r.taus, rtol=5e-6)
        np.testing.assert_array_equal([int(x[1]) for x in rows[1:]], r.n)
        for j in range(3):
            dev = [float(x[2 + 2 * j]) for x in rows[1:]]
            np.testing.assert_allclose(dev, r.dev[:, j], rtol=5e-6)
            lo_hi = [x[3 + 2 * j].split(" – ") for x in rows[1:]]
            np.testing.assert_allclose([float(a) for a, _ in lo_hi], r.ci_low[:, j], rtol=5e-6)
            np.testing.assert_allclose([float(b) for _, b in lo_hi], r.ci_high[:, j], rtol=5e-6)


def test_summary_section(built):
    rep, short, long = built
    md = rep.markdown.read_text()
    for heading in ("1. Recording summary", "2. Sample statistics", "3. Distribution fits",
                    "4. Allan deviation", "5. Noise coefficients", "6. Datasheet comparison"):
        assert f"## {heading}" in md
    assert f"| short | <test arrays> | arrays | {len(short)} |" in md
    assert f"| long | <test arrays> | arrays | {len(long)} |" in md


def test_html_embeds_every_image(built):
    rep, _, _ = built
    html = rep.html.read_text()
    srcs = re.findall(r'src="([^"]*)"', html)
    md_figs = re.findall(r"^!\[.*\]\((figures/[^)]*)\)$", rep.markdown.read_text(), re.M)
    assert len(srcs) == len(md_figs) == 15
    assert all(s.startswith("data:image/png;base64,") for s in srcs)
    assert "<script" not in html and "<link" not in html
    # links only within the page (the contents) and to the documentation site
    from imunoise.report.formatting import DOCS_URL

    assert all(h.startswith(("#", DOCS_URL)) for h in re.findall(r'href="([^"]*)"', html))
    for s in md_figs:
        assert (rep.out_dir / s).is_file()


def test_single_log_does_both(tmp_path):
    log = _vn_like(12000, 4)
    rep = report.build(log, None, tmp_path, progress=False)
    md = rep.markdown.read_text()
    assert "One log given" in md
    assert set(rep.allan) == {"gyro", "accel"}
    assert len(rep.allan["gyro"].taus) > 10


def test_model_files_and_tables_match_fit(built):
    from imunoise import export

    rep, _, long = built
    md = rep.markdown.read_text()
    data = json.loads((rep.out_dir / "noise.json").read_text())
    kalibr = {}
    for line in (rep.out_dir / "imu.yaml").read_text().splitlines():
        if ":" in line and not line.startswith("#"):
            key, value = line.split("#")[0].split(":", 1)
            kalibr[key.strip()] = value.strip()
    for sensor in ("gyro", "accel"):
        model = imunoise.fit(imunoise.adev(getattr(long, sensor), long.fs,
                                           taus=report.TAUS_PER_DECADE))
        for term in "QNBKR":
            written = [np.nan if v is None else v for v in data[sensor][term]["value"]]
            np.testing.assert_allclose(written, model.value(term), rtol=1e-12)
        rows = _md_table(md, f"{sensor} noise coefficients per axis")
        # in the report's units: one family per sensor (µg for the accelerometer)
        units = report.model_text.REPORT_UNITS[sensor]
        for want, got in zip(model.table(sensor, units=units), rows[1:], strict=True):
            assert got[1] == want["term"]
            for j, axis in enumerate("XYZ"):
                if not want[f"{axis}_supported"]:  # a value's 95 % bound, never 0
                    assert got[3 + j] == (display.upper_bound(want[f"{axis}_upper"])
                                          if want["missing"] == display.NOT_RESOLVED
                                          else want["missing"])
                    continue
                value, std = _value_std(got[3 + j])
                # GUM rounding: two significant digits of the std, the value to the same place
                assert std == pytest.approx(want[f"{axis}_std"], rel=0.05)
                assert value == pytest.approx(want[axis], abs=0.05 * want[f"{axis}_std"])
    want = export.kalibr_dict(gyro=rep.models["gyro"], accel=rep.models["accel"],
                              update_rate=long.fs)
    for key in ("gyroscope_noise_density", "accelerometer_noise_density",
                "gyroscope_random_walk", "accelerometer_random_walk", "update_rate"):
        assert float(kalibr[key]) == pytest.approx(want[key], rel=1e-5)
    cmp = _md_table(md, "Measured vs datasheet (vn100)")
    assert len(cmp) - 1 == len(imunoise.compare(rep.models, "vn100").rows)
    # the verdict word, then its remark in brackets ("typical (within a factor 1.5 of typical)")
    assert {r[-1].split(" (")[0] for r in cmp[1:]} <= set(datasheet.VERDICTS)


def test_report_on_bundled_real_log(tmp_path):
    from imunoise.cli import bundled_log

    rep = report.build(bundled_log(), None, tmp_path, progress=False)
    md = rep.markdown.read_text()
    assert "vn100_stationary_5min.txt" in md
    rows = _md_table(md, "Histogram bins: the sensor's quantization step and the "
                         "spacing of the levels it uses")
    steps = {r[0]: r[2] for r in rows[1:]}
    assert float(steps["gyro X"]) == pytest.approx(1e-6, rel=1e-3)
    assert float(steps["accel X"]) == pytest.approx(1e-3, rel=1e-3)
    # 5 minutes: a PSD section whose table explains the axes with lines; no dynamic map
    psd = _md_table(md, "gyro: noise density from the spectrum and from the Allan fit")
    remarks = {r[0]: r[-1] for r in psd[1:]}
    # the ADEV model's tone term takes the gyro's 18 Hz line, so both N agree on every axis
    assert all(remarks[a].startswith("agree") for a in "XYZ"), remarks
    accel = {r[0]: r[-1] for r in _md_table(
        md, "accel: noise density from the spectrum and from the Allan fit")[1:]}
    # agreement, or a named cause (a line, the sensor's filter), not the generic remark
    named = ("agree", "spectral line", "a spectral line", "the sensor's low-pass filter")
    assert all(r.startswith(named) for r in accel.values()), accel
    assert "Dynamic Allan deviation" not in md


def test_missing_file_is_oserror(tmp_path):
    with pytest.raises(OSError, match="does not exist"):
        report.build(tmp_path / "nope.txt", None, tmp_path / "out", progress=False)


def test_figures_listed(built):
    rep, _, _ = built
    assert all(Path(p).is_file() for p in rep.figures)
    assert len(rep.figures) == 30


def test_sections_are_numbered_from_the_list(built):
    rep, _, _ = built
    headings = re.findall(r"^## (\d+)\. (.*)$", rep.markdown.read_text(), re.M)
    # These logs carry no attitude or temperature, are too short for a warm-up and
    # come without logs of other sensors on their mount: those sections are absent
    # and the numbers close up.
    absent = ("Attitude", "Warm-up", "Temperature", "Sensors on one mount")
    present = [s.title for s in report.SECTIONS if not s.title.startswith(absent)]
    if not rep.markdown.read_text().count("## 4. Events"):
        present.remove("Events (vibration, shocks, spikes)")
    if not rep.markdown.read_text().count(". Events and the Allan deviation\n"):
        present.remove("Events and the Allan deviation")  # the long log has none
    assert headings == [(str(i), t) for i, t in enumerate(present, start=1)]


def test_psd_and_dynamic_sections(built):
    rep, _, _ = built
    md = rep.markdown.read_text()
    psd = md.split("## 7. Power spectral density")[1].split("\n## ")[0]
    assert psd.count("| X |") == 2 and "N PSD" in psd  # gyro and accel tables
    dadev = md.split("## 8. Dynamic Allan deviation")[1].split("\n## ")[0]
    assert dadev.count("noise is stationary") + dadev.count("noise is not stationary") == 2
