"""Report sections of issue 13: events, warm-up (and --trim auto), temperature; each
absent when it does not apply."""

import re
import warnings
from importlib import resources

import imunoise
import numpy as np
import pytest
from imunoise import report
from imunoise.cli import main

FS = 10.0
VN_LOG = resources.files("imunoise") / "data" / "vn100_stationary_5min.txt"


def warming_log(seed: int = 1, minutes: float = 90.0) -> imunoise.ImuLog:
    """A still log that warms (τ 8 min), with a 2 s burst in gyro X at 4000 s."""
    rng = np.random.default_rng(seed)
    n = int(minutes * 60 * FS)
    t = np.arange(n) / FS
    temp = 44 - 8 * np.exp(-t / 480)
    gyro = 1e-3 * rng.standard_normal((n, 3)) + 2e-3 * np.exp(-t / 480)[:, None]
    gyro += 1e-5 * (temp - 40)[:, None]
    gyro[40000:40020, 0] += 8e-3 * rng.standard_normal(20)
    accel = 0.01 * rng.standard_normal((n, 3)) + [0, 0, -9.81]
    return imunoise.ImuLog.from_arrays(FS, gyro=gyro, accel=accel, temperature=temp,
                                       source="<warming>")


def sections(markdown: str) -> list[str]:
    return re.findall(r"^## \d+\. (.+)$", markdown, flags=re.M)


@pytest.fixture(scope="module")
def trimmed(tmp_path_factory):
    log = warming_log()
    out = tmp_path_factory.mktemp("trimmed")
    rep = report.build(log, out_dir=out, spec=None, progress=False, trim="auto")
    return rep, log, rep.markdown.read_text(encoding="utf-8")


def test_sections_present_when_they_apply(trimmed):
    _rep, _log, md = trimmed
    titles = sections(md)
    for title in ("Events (vibration, shocks, spikes)", "Warm-up", "Temperature"):
        assert title in titles
    assert titles.index("Events (vibration, shocks, spikes)") < titles.index("Allan deviation")


def test_trim_auto_states_what_it_cut_and_the_analysis_uses_the_rest(trimmed):
    rep, log, md = trimmed
    found = imunoise.warmup(log)
    assert found.settle > 0
    cut = re.search(r"\*\*Trim\*\*: `--trim auto` cut the first (\d+) samples", md)
    assert cut and int(cut.group(1)) == found.settle_index
    (analysed,) = rep.logs
    assert len(analysed) == len(log) - found.settle_index
    # the Allan analysis is the trimmed log's
    expected = imunoise.adev(analysed.gyro, FS, taus=report.TAUS_PER_DECADE)
    np.testing.assert_allclose(rep.allan["gyro"].dev, expected.dev)


def test_event_found_and_listed(trimmed):
    _rep, _log, md = trimmed
    # times are from the first sample of the recording, trimmed part included
    table = md.split("Events of the log")[1].split("\n\n")[1]  # one log: not "short"
    row = re.search(r"\| 4000(\.\d+)? \| 400[12](\.\d+)? \| [\d.]+ \| burst \| gyro X \| "
                    r"[\d.]+ \| ([\d.]+) \(gyro X\) \|", table)
    assert row, table
    # the evidence: the burst against the quiet noise (RMS over the event ÷ quiet RMS)
    assert float(row.group(3)) > 3


def test_temperature_section_gives_datasheet_units_and_compensation(trimmed):
    rep, _log, md = trimmed
    section = md.split("## ")[[s.split("\n")[0] for s in md.split("## ")].index(
        next(s.split("\n")[0] for s in md.split("## ") if s.split("\n")[0].endswith("Temperature"))
    )]
    assert "°/h/°C" in section and "mg/°C" in section
    assert any(p.name == "thermal_adev_gyro.png" for p in rep.figures)


def test_short_log_without_temperature_has_events_only(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        log = imunoise.read(VN_LOG)
    rep = report.build(log, out_dir=tmp_path, spec=None, progress=False)
    titles = sections(rep.markdown.read_text(encoding="utf-8"))
    assert "Events (vibration, shocks, spikes)" in titles
    assert "Warm-up" not in titles and "Temperature" not in titles


def test_quiet_log_has_no_event_section(tmp_path):
    rng = np.random.default_rng(3)
    log = imunoise.ImuLog.from_arrays(FS, gyro=rng.standard_normal((6000, 3)),
                                      accel=rng.standard_normal((6000, 3)))
    rep = report.build(log, out_dir=tmp_path, spec=None, progress=False, trim="auto")
    md = rep.markdown.read_text(encoding="utf-8")
    assert "Events (vibration, shocks, spikes)" not in sections(md)
    assert "too short to examine its warm-up; nothing was cut" in md


def test_bad_trim(tmp_path):
    with pytest.raises(ValueError, match="trim must be None or 'auto'"):
        report.build(warming_log(), out_dir=tmp_path, trim="yes")


def test_cli_trim_option(tmp_path, capsys):
    assert main(["report", str(VN_LOG), "-o", str(tmp_path / "r"), "--fs", "40",
                 "--spec", "none", "--trim", "auto", "--no-progress"]) == 0
    assert "nothing was cut" in (tmp_path / "r" / "report.md").read_text(encoding="utf-8")
    assert main(["report", str(VN_LOG), "--trim", "always"]) == 2
    assert "--trim" in capsys.readouterr().err


def _section(md: str, title: str) -> str:
    return md.split(f". {title}\n")[1].split("\n## ")[0]


def test_long_log_events_with_and_without_in_the_allan_analysis(trimmed):
    rep, _log, md = trimmed
    titles = sections(md)
    assert titles.index("Events and the Allan deviation") > titles.index("Allan deviation")
    text = _section(md, "Events and the Allan deviation")
    (analysed,) = rep.logs
    found = imunoise.events(analysed)
    assert f"holds {len(found)} event" in text
    # the "without events" column is the gap-aware ADEV of the log with them left out
    cut = found.exclude(analysed, pad=0.2)
    row = re.search(r"\| gyro X \| rad/s \| 10(?:\.0)? s \| ([^|]+) \| ([^|]+) \|", text)
    assert row, text
    want = imunoise.adev(cut.gyro[:, 0], FS, taus=[10.0]).dev[0]
    assert float(row.group(2)) == pytest.approx(want, rel=0.01)


def test_events_that_change_the_allan_deviation_are_said_to(tmp_path):
    rng = np.random.default_rng(9)
    n = int(40 * 60 * FS)
    gyro = 1e-3 * rng.standard_normal((n, 3))
    for s in range(600, n - 100, 1200):  # a 5 s, 10σ shake every 2 minutes
        gyro[s:s + 50, 1] += 1e-2 * rng.standard_normal(50)
    accel = 0.01 * rng.standard_normal((n, 3))
    long = imunoise.ImuLog.from_arrays(FS, gyro=gyro, accel=accel, source="<shaken>")
    short = imunoise.ImuLog.from_arrays(FS, gyro=gyro[:3000], accel=accel[:3000],
                                        source="<short>")
    rep = report.build(short, long, out_dir=tmp_path, spec=None, progress=False)
    text = _section(rep.markdown.read_text(encoding="utf-8"), "Events and the Allan deviation")
    assert "The long log holds 2" in text and "(20 bursts" in text
    assert "change the Allan deviation beyond its 68.3 % confidence interval" in text
    assert re.search(r"gyro Y at 1(\.0)? s", text) and "gyro X at" not in text


def test_no_events_no_allan_events_section(tmp_path):
    rng = np.random.default_rng(4)
    log = imunoise.ImuLog.from_arrays(FS, gyro=rng.standard_normal((6000, 3)),
                                      accel=rng.standard_normal((6000, 3)))
    rep = report.build(log, out_dir=tmp_path, spec=None, progress=False)
    assert "Events and the Allan deviation" not in sections(
        rep.markdown.read_text(encoding="utf-8"))
