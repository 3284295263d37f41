"""imunoise events / imunoise thermal on the command line."""

from importlib import resources

import numpy as np
from imunoise.cli import main

VN_LOG = str(resources.files("imunoise") / "data" / "vn100_stationary_5min.txt")


def test_events_lists_the_gyro_x_bursts(capsys):
    assert main(["events", VN_LOG, "--fs", "40"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("# ") and "events" in out[0]
    rows = [line.split() for line in out[2:]]
    gyro_x = [(float(r[0]), float(r[1])) for r in rows if "gyro_X" in r[4]]
    for visible in (5, 90, 140, 185):
        assert any(a - 3 <= visible <= b + 3 for a, b in gyro_x)


def test_events_names_the_event_a_shock_lies_inside(tmp_path, capsys):
    from tests.events.test_events import burst
    from tests.events.test_onsets import _vibration

    fs = 40.0
    rng = np.random.default_rng(4)
    gyro = 1e-3 * rng.standard_normal((16_000, 3))
    gyro[2_000:10_000, 0] += 3e-3 * _vibration(8_000, fs, 9.0, rng)
    gyro[6_000:6_040, 0] += 1e-3 * burst(40, fs, 12.0, 0)
    rows = ["time,gyro_x,gyro_y,gyro_z"]
    rows += [f"{i / fs:.3f},{g[0]:.7f},{g[1]:.7f},{g[2]:.7f}" for i, g in enumerate(gyro)]
    path = tmp_path / "shock.csv"
    path.write_text("\n".join(rows) + "\n")
    assert main(["events", str(path)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[1].split()[-1] == "within"
    rows = [line.split() for line in out[2:]]
    inside = [r for r in rows if r[5] != "-"]
    assert len(inside) == 1 and abs(float(inside[0][0]) - 150.0) <= 0.1
    # the vibration is one event or a few (its envelope dips); the shock's is named
    parent = rows[int(inside[0][5])]
    assert 50 <= float(parent[0]) < 150 < float(parent[1]) <= 250.1


def test_thermal_prints_slopes_in_datasheet_units(tmp_path, capsys):
    fs, n = 10.0, 36_000
    rng = np.random.default_rng(2)
    temp = 30 + 10 * (1 - np.exp(-np.arange(n) / fs / 900))
    gyro = 1e-4 * rng.standard_normal((n, 3)) + 2e-5 * (temp - 35)[:, None]
    rows = ["time,gyro_x,gyro_y,gyro_z,temperature"]
    rows += [f"{i / fs:.1f},{g[0]:.8f},{g[1]:.8f},{g[2]:.8f},{t:.4f}"
             for i, (g, t) in enumerate(zip(gyro, temp, strict=True))]
    path = tmp_path / "warm.csv"
    path.write_text("\n".join(rows) + "\n")
    assert main(["thermal", str(path), "--degree", "2"]) == 0
    out = capsys.readouterr().out
    assert "bias vs temperature over 30" in out
    expected = 2e-5 * 180 / np.pi * 3600  # 4.125 °/h/°C
    slopes = [float(line.split()[1]) for line in out.splitlines() if line.strip().startswith(
        "gyro_")]
    assert len(slopes) == 3 and np.allclose(slopes, expected, rtol=0.05)
    assert "°/h/°C" in out and "quadratic" in out


def test_thermal_without_temperature_fails_in_one_line(capsys):
    assert main(["thermal", VN_LOG, "--fs", "40"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no temperature channel" in err[0]


def test_events_bad_false_alarm(capsys):
    assert main(["events", VN_LOG, "--fs", "40", "--false-alarm", "0.5"]) == 2
    assert "argument --false-alarm: must be in (0, 0.01); got '0.5'" in capsys.readouterr().err


def test_report_says_the_events_not_gaps_cut_the_comparisons_taus(tmp_path, capsys):
    # a live capture with no gaps, 30 % of it bursts: left out, they leave no
    # stretch long enough for tau 100 s; the warning named "the gaps in x" before
    from helpers.data import shared_file

    log = shared_file("data/vn100-ascii/live_capture.txt")
    assert main(["report", str(log), "--fs", "40", "-o", str(tmp_path / "r"),
                 "--spec", "none", "--no-progress"]) == 0
    err = capsys.readouterr().err
    line = next(w for w in err.splitlines() if "without its events" in w)
    assert line.startswith("imunoise: warning: the Allan deviation of the log without its "
                           "events stops at τ = 9.95 s (gyro, accel; 1 of the 4 compared "
                           "taus dropped): the 32 events left out")
    assert "leave no event-free stretch longer than 2.1 min, too short for τ = 99.5 s; " \
           "the log's length is not the limit" in line
    assert "`imunoise events LOG` lists them" in line
    assert "gaps in x" not in err and "taus dropped: the missing samples" not in err
    assert "stops at τ = 9.95 s" in (tmp_path / "r" / "report.md").read_text()
