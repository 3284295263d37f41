"""imunoise.fleet and ``imunoise fleet``: units compared with each other and a datasheet."""

from __future__ import annotations

import math
import re
import subprocess
import sys
import warnings

import imunoise
import numpy as np
import pytest
from imunoise._analysis import fleet as fleet_module
from imunoise._analysis.fleet import MIN_UNITS, Z_CUT, cut, robust_z
from imunoise._simulation.log import noise_of_spec
from imunoise.cli import main
from imunoise.scale.batch import _base_row

NOISY = 2  # the unit with three times the white noise (unit3.bin)
VN100_GYRO_N = 0.0035  # °/s/√Hz, the datasheet's typical noise density


@pytest.fixture(scope="module")
def units(tmp_path_factory):
    """Four simulated VN-100s, 30 min at 40 Hz; unit3 has 3× the white noise of
    gyro and accelerometer."""
    d = tmp_path_factory.mktemp("fleet")
    paths = []
    for i in range(4):
        noise = noise_of_spec("vn100")
        if i == NOISY:
            for terms in noise.values():
                terms["N"] *= 3.0
        paths.append(imunoise.simulate_log(d / f"unit{i + 1}.bin", 0.5, 40.0,
                                           format="vn-binary", spec=noise, seed=100 + i))
    return d, paths


@pytest.fixture(scope="module")
def result(units):
    _, paths = units
    return imunoise.fleet(paths, client=False)


def test_the_noisy_unit_alone_is_the_outlier_on_n(result):
    names = ["unit1.bin", "unit2.bin", "unit3.bin", "unit4.bin"]
    assert result.names == tuple(names)
    noisy = names[NOISY]
    # every axis of both sensors: unit3 is the one outlier on N, about 3× the median
    on_n = {(o["sensor"], o["axis"]): o for o in result.outliers if o["term"] == "N"}
    assert set(on_n) == {(s, a) for s in ("gyro", "accel") for a in "XYZ"}
    for o in on_n.values():
        assert o["unit"] == noisy
        assert 2.7 < o["ratio"] < 3.3, o
        assert o["z"] > o["cut"] >= Z_CUT
    # and no other unit stands out anywhere, on any coefficient
    assert {o["unit"] for o in result.outliers} == {noisy}
    for u in result.units:
        assert bool(u["outliers"]) == (u["unit"] == noisy)
    for s in result.stats:
        if s["term"] == "N":
            assert s["outliers"] == (noisy,) and s["resolved"] == 4 and s["judged"]


def test_median_and_spread_are_over_resolved_units(result):
    gyro_n = [s for s in result.stats if s["sensor"] == "gyro" and s["term"] == "N"]
    for s in gyro_n:  # the median ignores the noisy unit: the datasheet value
        assert abs(s["median"] / VN100_GYRO_N - 1) < 0.03, s
        assert s["label"] == "°/s/√Hz" and 0 < s["sigma"] < 0.05
    partial = [s for s in result.stats if 0 < s["resolved"] < s["units"]]
    assert partial, "a coefficient some units do not resolve (K, Q, R)"
    for s in partial + gyro_n:
        rows = [r for r in result.rows if (r["sensor"], r["term"], r["axis"])
                == (s["sensor"], s["term"], s["axis"])]
        values = np.array([r["value"] for r in rows])
        resolved = values[np.isfinite(values)]
        assert len(resolved) == s["resolved"]
        assert s["median"] == pytest.approx(math.exp(np.median(np.log(resolved))))
        for r in rows:  # a value not resolved is NaN, with its bound, and never judged
            if not r["resolved"]:
                assert math.isnan(r["value"]) and math.isnan(r["z"]) and not r["outlier"]
        if s["resolved"] < MIN_UNITS:
            assert not s["judged"] and s["cut"] == math.inf and not s["outliers"]


def test_verdicts_are_those_of_compare(units, result):
    _, paths = units
    for path, u in zip(paths, result.units, strict=True):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            log = imunoise.read(path)
        models = {s: imunoise.fit(imunoise.adev(getattr(log, s), log.fs, taus=10))
                  for s in ("gyro", "accel")}
        cmp = imunoise.compare(models, "vn100")
        want = {(r["sensor"], r["term"], r["axis"]): r["verdict"] for r in cmp.rows}
        got = {(r["sensor"], r["term"], r["axis"]): r["verdict"] for r in result.rows
               if r["unit"] == u["unit"] and r["verdict"] is not None}
        assert got == want
        assert u["passed"] == cmp.passed
        assert set(u["failed"]) == {f"{s} {t} {a}" for (s, t, a), w in want.items()
                                    if w == "fail"}


def test_result_views(result):
    rows = result.table()
    assert len(rows) == 4 * 2 * 3 * 5  # units × sensors × axes × (N, B, K, Q, R)
    assert {r["unit"] for r in rows} == set(result.names)
    text = result.text()
    for name in result.names:
        assert name in text
    assert "1.4826·MAD" in text and "unit3.bin" in text.split("Outliers")[1]
    head = repr(result)
    assert head.startswith("Fleet(4 units") and "unit3.bin" in head and len(head) <= 300
    html = result._repr_html_()
    assert html.startswith("<table>") and all(n in html for n in result.names)


def test_cli_fleet_writes_one_report_naming_every_unit(units, tmp_path, capsys):
    _, paths = units
    out = tmp_path / "report"
    assert main(["fleet", *map(str, paths), "-o", str(out), "--serial"]) == 0
    said = capsys.readouterr().out
    assert "4 units" in said and "unit3.bin gyro N" in said
    md = (out / "fleet.md").read_text(encoding="utf-8")
    html = (out / "fleet.html").read_text(encoding="utf-8")
    for name in ("unit1.bin", "unit2.bin", "unit3.bin", "unit4.bin"):
        assert name in md and name in html
    # the outlier table: unit3 on N, nothing else
    section = md.split("## 2. Outliers")[1].split("## 3.")[0]
    table = [line.split(" | ") for line in section.splitlines()
             if line.startswith("| unit") and not line.startswith("| unit |")]
    assert {(c[0].strip("| "), c[3]) for c in table} == {("unit3.bin", "N")}
    assert len(table) == 6
    # one figure per coefficient across units, embedded in the HTML
    for sensor in ("gyro", "accel"):
        for term in ("N", "B"):
            assert (out / "figures" / f"fleet_{sensor}_{term}.png").is_file()
    assert html.count("<img src=\"data:image/png;base64,") == md.count("![")
    assert "imunoise-report.json" in {p.name for p in out.iterdir()}
    # a second run updates the same folder
    assert main(["fleet", *map(str, paths[:3]), "-o", str(out), "--serial", "--spec",
                 "none"]) == 0
    assert "unit4.bin" not in (out / "fleet.md").read_text(encoding="utf-8")


def test_cli_fleet_bad_input_is_one_line_exit_2(units, tmp_path, capsys):
    d, paths = units
    cases = [
        [str(d / "missing.bin"), "--serial"],
        [str(d / "nothing*.bin"), "--serial"],
        [str(paths[0]), "--serial", "--spec", "no-such-sheet"],
        [str(paths[0]), "--serial", "--scheduler", "tcp://127.0.0.1:1"],
    ]
    for extra in cases:
        capsys.readouterr()
        assert main(["fleet", *extra, "-o", str(tmp_path / "r")]) == 2, extra
        err = capsys.readouterr().err
        assert err.startswith("imunoise: error: ") and err.count("\n") == 1, err
    junk = tmp_path / "junk.bin"
    junk.write_bytes(b"\x00\x17 not a log " * 100)
    assert main(["fleet", str(junk), "-o", str(tmp_path / "r2"), "--serial"]) == 2
    assert "no log could be analysed" in capsys.readouterr().err
    # a report never lands on an input
    assert main(["fleet", str(paths[0]), "-o", str(paths[0]), "--serial"]) == 2


def test_cli_fleet_ctrl_c_exits_130(units, tmp_path, monkeypatch, capsys):
    _, paths = units

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(fleet_module, "analyse_logs", interrupted)
    assert main(["fleet", *map(str, paths), "-o", str(tmp_path / "r"), "--serial"]) == 130
    assert "interrupted" in capsys.readouterr().err
    assert not (tmp_path / "r").exists()


def test_a_log_that_fails_is_named_and_left_out(units, tmp_path):
    _, paths = units
    junk = tmp_path / "junk.bin"
    junk.write_bytes(b"\x00\x17 not a log " * 100)
    f = imunoise.fleet([*paths, junk], client=False, spec=None)
    assert f.names[-1] == "junk.bin" and f.units[-1]["error"]
    assert "junk.bin" not in f.analysed and all(r["unit"] != "junk.bin" for r in f.rows)
    assert all(u["passed"] is None for u in f.units)  # no spec: no verdicts
    assert {o["unit"] for o in f.outliers} == {"unit3.bin"}


def _rows(path: str, values: dict[str, float], std: float = 0.0) -> list[dict]:
    """analyse_log rows of a one-axis gyro with given N/B (rad units); others NaN."""
    row = _base_row(path)
    row.update(sensor="gyro", axis="X", format="csv", samples=1000, fs=40.0, duration_s=25.0)
    for t, v in values.items():
        ok = math.isfinite(v)
        row.update({t: v, f"{t}_std": std * v if ok else math.nan,
                    f"{t}_upper": math.nan if ok else 1e-3, f"{t}_supported": ok})
    return [row]


def test_small_fleets_and_unresolved_values_are_handled_honestly():
    # two units: each is as far from the median as the other, so none is judged
    two = fleet_module._compare(["a", "b"], [_rows("a", {"N": 1e-4}), _rows("b", {"N": 9e-4})],
                                None, 0.01)
    (n,) = [s for s in two.stats if s["term"] == "N"]
    assert n["resolved"] == 2 and not n["judged"] and not two.outliers
    # five units, one not resolving B: B's median over four, one unit 10× on N
    vals = [1.00, 1.02, 0.98, 1.01, 10.0]
    results = [_rows(f"u{i}", {"N": 1e-4 * v, "B": (1e-5 * v if i != 2 else math.nan)},
                     std=0.005) for i, v in enumerate(vals)]
    f = fleet_module._compare([f"u{i}" for i in range(5)], results, None, 0.01)
    b = next(s for s in f.stats if s["term"] == "B")
    assert (b["resolved"], b["units"]) == (4, 5)
    assert sorted((o["unit"], o["term"]) for o in f.outliers) == [("u4", "B"), ("u4", "N")]
    row = next(r for r in f.rows if r["unit"] == "u2" and r["term"] == "B")
    assert math.isnan(row["value"]) and row["upper"] > 0 and not row["outlier"]
    # a unit whose own estimate is very uncertain is not called an outlier for it
    results[4] = _rows("u4", {"N": 1e-4 * 1.5}, std=0.5)
    f = fleet_module._compare([f"u{i}" for i in range(5)], results, None, 0.01)
    assert not f.outliers


def test_robust_z_and_cut():
    med, sigma, z = robust_z([1.0, 1.1, np.nan, 0.9, 5.0])
    assert math.isnan(z[2]) and med == pytest.approx(math.sqrt(1.0 * 1.1))
    assert sigma == pytest.approx(1.4826 * np.median(np.abs(np.log([1, 1.1, .9, 5])
                                                            - np.log(med))))
    assert z[4] > 10 > abs(z[0])
    assert cut(2) == math.inf and cut(MIN_UNITS) > cut(4) > 10
    assert Z_CUT <= cut(100) < 5 and cut(10) < cut(4)
    with pytest.raises(ValueError, match="false_alarm"):
        cut(10, 0.7)


@pytest.mark.parametrize("n", [4, 10])
def test_false_outliers_are_rare_in_a_fleet_without_outliers(n):
    # log-normal fleets with a 20 % unit-to-unit spread and no outlier: the
    # calibrated cut flags one at most about 1 % of the time, the bare 3.5 far more
    rng = np.random.default_rng(7)
    fleets = np.exp(0.2 * rng.standard_normal((3000, n)))
    flagged = bare = 0
    for v in fleets:
        _, _, z = robust_z(v)
        flagged += bool(np.any(np.abs(z) > cut(n)))
        bare += bool(np.any(np.abs(z) > Z_CUT))
    assert flagged / len(fleets) < 0.02
    assert bare / len(fleets) > 0.08


def test_dask_gives_the_serial_numbers(units, result):
    distributed = pytest.importorskip("distributed")
    _, paths = units
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        parallel = imunoise.fleet(paths, client=client)
    def same(a: dict, b: dict) -> bool:  # NaN (not resolved) equals NaN here
        return a.keys() == b.keys() and all(
            a[k] == b[k] or (isinstance(a[k], float) and math.isnan(a[k]) and math.isnan(b[k]))
            for k in a)

    assert len(parallel.rows) == len(result.rows)
    assert all(same(a, b) for a, b in zip(parallel.rows, result.rows, strict=True))
    assert all(same(a, b) for a, b in zip(parallel.stats, result.stats, strict=True))
    assert parallel.outliers == result.outliers and parallel.units == result.units


def test_computing_a_fleet_loads_no_plotting():
    code = ("import sys, imunoise._analysis.fleet; "
            "sys.exit(any(m in sys.modules for m in ('matplotlib', 'imunoise.plot', "
            "'imunoise.report')))")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


def test_public_name():
    assert "fleet" in imunoise.__all__ and imunoise.fleet.__module__ == "imunoise._analysis.fleet"
    assert re.search(r"Parameters\n\s+-+", imunoise.fleet.__doc__)
