"""The imunoise command line: exit codes and one-line errors, never a traceback."""

import subprocess
import sys

import imunoise
import numpy as np
import pytest
from imunoise.cli import main
from imunoise.display import format_value


@pytest.fixture
def read():
    return imunoise.read


def _run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def _one_line_error(err):
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("imunoise: error: ")
    assert "Traceback" not in err
    return lines[0]


@pytest.mark.parametrize("cmd", ["stats", "adev", "fit", "convert", "report"])
def test_missing_file(cmd, tmp_path, capsys):
    argv = [cmd, str(tmp_path / "missing.txt")]
    if cmd == "convert":
        argv += ["-o", str(tmp_path / "x.csv")]
    code, _, err = _run(argv, capsys)
    assert code == 2
    assert "missing.txt" in _one_line_error(err)


@pytest.mark.parametrize(
    "argv",
    [
        [],
        ["nonsense"],
        ["adev", "x.txt", "--kind", "bogus"],
        ["adev"],
        ["report", "a", "b", "c"],
        ["demo", "--hours", "-1"],
        ["simulate", "-o", "x.txt", "--fs", "abc"],
        ["stats", "--no-such-option", "x"],
    ],
)
def test_bad_options(argv, capsys):
    code, _, err = _run(argv, capsys)
    assert code == 2
    if argv:
        _one_line_error(err)


def test_convert_rejects_unknown_suffix(tmp_path, capsys):
    f = tmp_path / "log.txt"
    f.write_text("x")
    code, _, err = _run(["convert", str(f), "-o", str(tmp_path / "out.xlsx")], capsys)
    assert code == 2 and ".xlsx" in _one_line_error(err)


@pytest.mark.parametrize("cmd", ["report", "adev", "fit", "stats", "convert", "simulate", "demo"])
def test_help(cmd, capsys):
    with pytest.raises(SystemExit) as exc:
        main([cmd, "--help"])
    assert exc.value.code == 0
    assert "usage: imunoise " + cmd in capsys.readouterr().out


def test_version(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"imunoise {imunoise.__version__}"


def test_subprocess_no_traceback(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-c", "import sys; from imunoise.cli import main; sys.exit(main())",
         "stats", str(tmp_path / "nope.bin")],
        capture_output=True, text=True, timeout=60,
    )
    assert proc.returncode == 2
    assert proc.stdout == ""
    _one_line_error(proc.stderr)


def test_unreadable_and_empty_logs(tmp_path, capsys):
    garbage = tmp_path / "garbage.bin"
    garbage.write_bytes(bytes(range(256)) * 20)
    code, _, err = _run(["stats", str(garbage)], capsys)
    assert code == 2
    _one_line_error(err)
    empty = tmp_path / "empty.txt"
    empty.write_text("")
    code, _, err = _run(["adev", str(empty)], capsys)
    assert code == 2
    _one_line_error(err)


def test_stats_adev_convert_on_bundled_log(tmp_path, capsys, read):
    from imunoise.cli import bundled_log

    log = read(bundled_log())
    code, out, _ = _run(["stats", str(bundled_log())], capsys)
    assert code == 0 and "gyro X" in out
    d = imunoise.distribution(log.accel[:, 2])
    assert imunoise.display.format_value(d.mu, d.mu_std) in out  # μ rounded to its uncertainty
    code, out, _ = _run(["adev", str(bundled_log()), "--sensor", "gyro"], capsys)
    assert code == 0
    rows = [line.split() for line in out.splitlines()[2:]]
    r = imunoise.adev(log.gyro, log.fs)
    np.testing.assert_allclose([float(x[0]) for x in rows], r.taus, rtol=1e-5)
    dev, low, high = (np.array([float(x[k]) for x in rows]) for k in (2, 3, 4))
    # GUM rounding: to two significant digits of the shorter arm of the interval
    arm = np.minimum(r.dev[:, 0] - r.ci_low[:, 0], r.ci_high[:, 0] - r.dev[:, 0])
    last_digit = 10.0 ** (np.floor(np.log10(arm)) - 1)
    assert np.all(np.abs(dev - r.dev[:, 0]) <= 0.5 * last_digit * (1 + 1e-9))
    assert np.all(np.abs(low - r.ci_low[:, 0]) <= 0.5 * last_digit * (1 + 1e-9))
    assert np.all(np.abs(high - r.ci_high[:, 0]) <= 0.5 * last_digit * (1 + 1e-9))
    assert np.all(last_digit > 1e-6 * r.dev[:, 0])  # not six noise digits
    for suffix in (".csv", ".npz", ".parquet"):
        out_file = tmp_path / f"log{suffix}"
        code, _, _ = _run(["convert", str(bundled_log()), "-o", str(out_file)], capsys)
        assert code == 0 and out_file.is_file()
    z = np.load(tmp_path / "log.npz")
    np.testing.assert_array_equal(z["gyro_x"], log.gyro[:, 0])
    csv = np.loadtxt(tmp_path / "log.csv", delimiter=",", skiprows=1)
    assert csv.shape[0] == len(log)


def test_report_command_on_bundled_log(tmp_path, capsys, read):
    from imunoise.cli import bundled_log

    code, out, err = _run(["report", str(bundled_log()), "-o", str(tmp_path / "r"),
                           "--spec", "none", "--no-progress"], capsys)
    assert code == 0, err
    assert out.strip() == f"report written to {tmp_path / 'r' / 'report.html'}"
    md = (tmp_path / "r" / "report.md").read_text()
    assert "| both | vn100_stationary_5min.txt |" in md


def test_demo(tmp_path, capsys, read):
    code, out, err = _run(["demo", "-o", str(tmp_path / "demo"), "--hours", "0.2",
                           "--no-progress"], capsys)
    assert code == 0, err
    assert str((tmp_path / "demo" / "report.html").resolve()) in out
    md = (tmp_path / "demo" / "report.md").read_text()
    assert "| long | <simulated VectorNav VN-100, 0.2 h> |" in md


def test_simulate_writes_a_readable_vn_log(tmp_path, capsys):
    out = tmp_path / "still.txt"
    code, _, err = _run(["simulate", "-o", str(out), "--hours", "0.01", "--seed", "3"], capsys)
    assert code == 0, err
    log = imunoise.read(out, fs=40.0)
    assert len(log) == 1440 and log.issues.total == 0
    assert log.accel[:, 2].mean() == pytest.approx(-9.80665, abs=0.01)
    assert log.gyro.std(axis=0) == pytest.approx([6.1e-5 * np.sqrt(40)] * 3, rel=0.1)


def test_fit_prints_datasheet_table(capsys, read):
    from imunoise import report
    from imunoise.cli import bundled_log

    code, out, err = _run(["fit", str(bundled_log()), "--sensor", "gyro", "--fs", "40"], capsys)
    assert code == 0, err
    log = read(bundled_log(), fs=40.0)
    model = imunoise.fit(imunoise.adev(log.gyro, log.fs, taus=report.TAUS_PER_DECADE))
    lines = out.splitlines()
    assert lines[0] == "# gyro"
    n_row = next(line for line in lines if " N " in f" {line} " and "deg/sqrt(h)" in line)
    want = next(r for r in model.table("gyro") if r["term"] == "N")
    assert format_value(want["X"], want["X_std"]) in n_row  # rounded to its uncertainty


def test_fit_table_lists_the_gauss_markov_and_tone_terms(capsys, read):
    from imunoise import report
    from imunoise.cli import bundled_log

    code, out, err = _run(["fit", str(bundled_log()), "--sensor", "gyro", "--fs", "40"], capsys)
    assert code == 0, err
    log = read(bundled_log(), fs=40.0)
    model = imunoise.fit(imunoise.adev(log.gyro, log.fs, taus=report.TAUS_PER_DECADE))
    # The bundled gyro's model: a tone on X and Y (the 18 Hz line), none on Z.
    others = [r for r in model.table("gyro") if r["term"] not in "QNBKR"]
    assert {r["term"] for r in others} >= {"A", "f0"}
    lines = out.splitlines()
    for row in others:
        line = next(ln for ln in lines if f" {row['term']} " in f" {ln} ")
        for axis in "XYZ":
            if row[f"{axis}_supported"]:
                assert format_value(row[axis], row[f"{axis}_std"]) in line, (row, line)
        assert "—" in line  # the axes whose model has no such term


def test_fit_with_bootstrap_uncertainties(capsys, read):
    from imunoise import report
    from imunoise.cli import bundled_log

    args = ["fit", str(bundled_log()), "--sensor", "gyro", "--fs", "40", "--bootstrap", "6"]
    code, out, err = _run(args, capsys)
    assert code == 0, err
    log = read(bundled_log(), fs=40.0)
    result = imunoise.adev(log.gyro, log.fs, taus=report.TAUS_PER_DECADE)
    model = imunoise.fit(result, uncertainty="bootstrap", replicates=6, seed=0)
    n_row = next(line for line in out.splitlines() if " N " in f" {line} ")
    want = next(r for r in model.table("gyro") if r["term"] == "N")
    assert format_value(want["X"], want["X_std"]) in n_row

    code, _, err = _run(args[:-1] + ["3"], capsys)
    assert code == 2 and "--bootstrap must be >= 5" in _one_line_error(err)


@pytest.mark.parametrize("suffix", [".csv", ".npz", ".parquet"])
def test_convert_quaternion_columns_round_trip(tmp_path, capsys, suffix):
    """Readers store the quaternion x, y, z, w: every writer names its columns so."""
    from imunoise import scale

    if suffix == ".parquet":
        pytest.importorskip("pyarrow")
    n = 50
    q = np.random.default_rng(3).normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    src = tmp_path / "q.csv"
    rows = np.column_stack([np.arange(n) / 10.0, np.zeros((n, 3)), q])
    np.savetxt(src, rows, delimiter=",", header="time,gx,gy,gz,qx,qy,qz,qw", comments="",
               fmt="%.9f")
    log = imunoise.read(src)
    np.testing.assert_allclose(log.quaternion, q, atol=1e-9)
    out = tmp_path / f"out{suffix}"  # not q.csv: that is the input
    assert main(["convert", str(src), "-o", str(out)]) == 0
    capsys.readouterr()
    if suffix == ".npz":
        z = np.load(out)
        cols = {a: z[f"quaternion_{a}"] for a in "xyzw"}
    elif suffix == ".parquet":
        import pyarrow.parquet as pq

        table = pq.read_table(out)
        cols = {a: table.column(f"quaternion_{a}").to_numpy() for a in "xyzw"}
        np.testing.assert_allclose(scale.load(out).quaternion, q, atol=1e-9)
    else:
        back = imunoise.read(out)
        np.testing.assert_allclose(back.quaternion, q, atol=1e-9)
        import csv

        header = next(csv.reader(open(out)))
        data = np.loadtxt(out, delimiter=",", skiprows=1)
        cols = {a: data[:, header.index(f"quaternion_{a}")] for a in "xyzw"}
    for j, a in enumerate("xyzw"):
        np.testing.assert_allclose(cols[a], q[:, j], atol=1e-9, err_msg=a)


def test_psd_command(tmp_path, capsys):
    from imunoise.cli import bundled_log

    code, out, _ = _run(["psd", str(bundled_log()), "--fs", "40", "--bins", "5",
                         "--plot", str(tmp_path / "psd.png")], capsys)
    assert code == 0
    n_lines = [line for line in out.splitlines() if line.startswith("# N ")]
    assert len(n_lines) == 3 and all("rad/s/sqrt(Hz)" in line for line in n_lines)
    log = imunoise.read(bundled_log(), fs=40.0)
    s = imunoise.psd(log.gyro, 40.0)
    assert format_value(s.N[0], s.N_std[0]) in n_lines[0]
    assert (tmp_path / "psd.png").read_bytes()[:4] == b"\x89PNG"
    code, out, _ = _run(["psd", str(bundled_log()), "--fs", "40", "--band", "1", "5"], capsys)
    assert code == 0 and "white band 1-5 Hz, given" in out


def test_psd_command_leaves_out_segments_with_a_missing_sample(tmp_path, capsys):
    from imunoise.cli import bundled_log

    lines = bundled_log().read_text().splitlines(keepends=True)
    lines[5000] = lines[5000][:20] + "X" + lines[5000][21:]  # checksum fails: one gap
    path = tmp_path / "gap.txt"
    path.write_text("".join(lines))
    code, out, err = _run(["psd", str(path), "--fs", "40"], capsys)
    assert code == 0 and "# N X = " in out
    assert "2 of " in err and "Welch segments hold one and are left out" in err


def test_dadev_command(tmp_path, capsys):
    from imunoise.cli import bundled_log

    code, out, _ = _run(["dadev", str(bundled_log()), "--fs", "40", "--window", "60",
                         "--step", "10", "--plot", str(tmp_path / "d.png")], capsys)
    assert code == 0
    assert "28 windows of 60 s every 10 s" in out
    assert "outside_CI" in out and (tmp_path / "d.png").is_file()


@pytest.mark.parametrize("argv, message", [
    (["psd", "--bins", "0"], "argument --bins: must be in [1, 1000]; got '0'"),
    (["psd", "--band", "5", "1"], "band must satisfy"),
    (["dadev", "--window", "1000"], "window must hold between 3"),
])
def test_psd_dadev_errors(argv, message, capsys):
    from imunoise.cli import bundled_log

    code, _, err = _run([argv[0], str(bundled_log()), "--fs", "40", *argv[1:]], capsys)
    assert code == 2
    assert message in _one_line_error(err)


def test_stats_has_attitude_and_plot_options(tmp_path, capsys, read):
    """yaw/pitch/roll in `stats` (and describe), `--plot` on stats, adev and fit."""
    from imunoise.cli import bundled_log

    log = read(bundled_log(), fs=40.0)
    desc = imunoise.describe(log)
    assert desc.names[-3:] == ("yaw", "pitch", "roll") and desc.units[-1] == "deg"
    yaw = log.ypr[:, 0]
    assert -180 < desc.mean[desc.names.index("yaw")] <= 180
    assert desc.std[desc.names.index("pitch")] == pytest.approx(np.std(log.ypr[:, 1], ddof=1))
    assert desc.std[desc.names.index("yaw")] <= np.std(yaw, ddof=1) * (1 + 1e-12)
    code, out, _ = _run(["stats", str(bundled_log()), "--fs", "40",
                         "--plot", str(tmp_path / "h.png")], capsys)
    assert code == 0
    table_rows = [line.split()[0] for line in out.splitlines() if line.strip()]
    assert table_rows.count("yaw") == 2 and table_rows.count("roll") == 2  # both tables
    for sensor in ("gyro", "accel", "mag", "ypr"):
        png = tmp_path / f"h_{sensor}.png"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and f"# figure: {png}" in out
    code, out, _ = _run(["adev", str(bundled_log()), "--fs", "40", "--sensor", "accel",
                         "--plot", str(tmp_path / "a.png")], capsys)
    assert code == 0 and (tmp_path / "a.png").stat().st_size > 1000
    code, out, _ = _run(["fit", str(bundled_log()), "--fs", "40", "--sensor", "gyro",
                         "--plot", str(tmp_path / "f.png")], capsys)
    assert code == 0 and (tmp_path / "f.png").stat().st_size > 1000
    assert f"# figure: {tmp_path / 'f.png'}" in out


def test_fit_prints_datasheet_units_when_asked(capsys):
    from imunoise.cli import bundled_log

    args = ["fit", str(bundled_log()), "--sensor", "gyro", "--fs", "40"]
    code, out, err = _run([*args, "--datasheet-units"], capsys)
    assert code == 0, err
    n_row = next(ln for ln in out.splitlines() if " N " in f" {ln} ")
    assert "deg/s/sqrt(Hz)" in n_row
    code, out, err = _run(args, capsys)
    assert "deg/sqrt(h)" in next(ln for ln in out.splitlines() if " N " in f" {ln} ")
