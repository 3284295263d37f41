"""Time integrity: every reader finds dropouts, keeps them as NaN rows and reports them."""

from __future__ import annotations

import io
from pathlib import Path

import imunoise
import numpy as np
import pytest
from helpers.vn_sentences import ymr
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from imunoise.readers.grid import Gaps, TimeGrid
from imunoise.readers.log import ImuLog
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin
from rosbags.typesys import Stores, get_typestore
from test_rosbag_reader import _imu, _write

DATA = Path(__file__).parents[1] / "data"
ROS1_REAL = Path("/work/shared/data/vn100-ros/ros1_stationary.bag")


def _runs(dropped: np.ndarray) -> list[tuple[int, int]]:
    """(first index, length) of the runs of consecutive dropped indices."""
    runs: list[tuple[int, int]] = []
    for i in np.sort(dropped):
        if runs and runs[-1][0] + runs[-1][1] == i:
            runs[-1] = (runs[-1][0], runs[-1][1] + 1)
        else:
            runs.append((int(i), 1))
    return runs


def _gap_list(gaps: Gaps) -> list[tuple[int, int]]:
    return [(int(i), int(s)) for i, s in zip(gaps.index, gaps.samples, strict=True)]


# -- the grid builder ------------------------------------------------------------------


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(50, 3000),
    fs=st.sampled_from([5.0, 30.0, 40.0, 100.0, 200.0, 800.0]),
    jitter=st.floats(0.0, 0.2),
    ppm=st.floats(-200.0, 200.0),
    t_start=st.floats(0.0, 2e9),
    ms_clock=st.booleans(),
    seed=st.integers(0, 2**32 - 1),
    drop_share=st.floats(0.0, 0.5),
)
def test_grid_finds_exactly_the_dropped_samples(
    n, fs, jitter, ppm, t_start, ms_clock, seed, drop_share
):
    """Timestamps with uniform jitter up to ±0.2 steps, a clock rate error, a 1 ms clock
    resolution (at up to 200 Hz) and random dropouts (single samples and runs): the
    gaps are exactly the dropped runs."""
    rng = np.random.default_rng(seed)
    dt = (1 + ppm * 1e-6) / fs
    t = t_start + np.arange(n) * dt + rng.uniform(-jitter, jitter, n) * dt
    if ms_clock and fs <= 200:
        t = np.round(t * 1e3) / 1e3
    n_runs = int(drop_share * n / 4)
    drop = np.zeros(n, dtype=bool)
    for start in rng.integers(1, n - 1, n_runs):
        drop[start : min(start + int(rng.integers(1, 20)), n - 1)] = True
    keep = np.flatnonzero(~drop)
    # The documented scope: the record keeps most of its samples (a handful of
    # jittered stamps cannot fix the step to a fifth of itself).
    assume(keep.size >= max(40, n // 2))
    grid = TimeGrid.from_timestamps(t[keep])
    assert grid.n == n
    assert grid.duplicate_time == 0 and grid.time_reversed == 0
    np.testing.assert_array_equal(grid.slot, keep)
    assert _gap_list(grid.gaps(grid.fs)) == _runs(np.flatnonzero(drop))
    # the rate to within the end points' jitter (and 1 ms ticks) over the span
    assert grid.fs == pytest.approx(1 / dt, rel=1e-6 + 2 * (jitter + 0.2) / n)


def test_grid_duplicates_and_reversals_are_counted_not_sorted():
    t = np.arange(10) / 10.0
    dup = np.insert(t, 4, t[3])  # sample 3 stamped twice
    g = TimeGrid.from_timestamps(dup)
    assert (g.n, g.duplicate_time, g.time_reversed) == (10, 1, 0)
    assert g.slot[4] == -1 and g.valid.all()

    rev = t.copy()
    rev[[5, 6]] = rev[[6, 5]]
    g = TimeGrid.from_timestamps(rev)
    assert (g.n, g.duplicate_time, g.time_reversed) == (10, 0, 1)
    assert list(g.slot) == [0, 1, 2, 3, 4, 6, 5, 7, 8, 9]  # placed by its time
    values = np.arange(10.0)
    np.testing.assert_array_equal(g.place(values), values[[0, 1, 2, 3, 4, 6, 5, 7, 8, 9]])


def test_grid_from_missing_positions():
    g = TimeGrid.from_missing(5, [0, 2, 2, 4, 5])  # 0 and 5 are the ends: not gaps
    assert g.n == 8
    assert list(g.slot) == [0, 1, 4, 5, 7]
    assert _gap_list(g.gaps(40.0)) == [(2, 2), (6, 1)]
    assert TimeGrid.from_missing(3, []).is_identity


def test_gaps_table():
    gaps = Gaps(index=[10, 100], samples=[5, 50], fs=10.0, t0=2.0)
    np.testing.assert_allclose(gaps.start, [3.0, 12.0])
    np.testing.assert_allclose(gaps.duration, [0.5, 5.0])
    np.testing.assert_allclose(gaps.end, [3.5, 17.0])
    assert gaps.total == 55 and len(gaps) == 2
    assert _gap_list(gaps.largest(1)) == [(100, 50)]
    assert gaps.rows() == [(3.0, 0.5, 5), (12.0, 5.0, 50)]
    assert gaps.valid(200).sum() == 145
    assert "2 gap(s)" in str(gaps) and str(Gaps.none(1.0)) == "no gaps"


# -- ImuLog ----------------------------------------------------------------------------


def test_from_arrays_nan_rows_are_gaps():
    gyro = np.zeros((100, 3))
    gyro[10:15] = np.nan
    gyro[50, 1] = np.nan
    log = ImuLog.from_arrays(10.0, gyro=gyro)
    assert _gap_list(log.gaps) == [(10, 5), (50, 1)]
    assert log.valid.sum() == 94
    assert log.issues.samples_missing == 6 and log.issues.gaps == 2
    assert log.issues.share_missing == pytest.approx(0.06)
    assert "6 samples missing (6 %) in 2 gaps" in str(log.issues)
    assert log.duration == 10.0
    assert str(ImuLog.from_arrays(10.0, gyro=np.zeros((5, 3))).issues) == "no issues"


# -- CSV -------------------------------------------------------------------------------


def _csv(t: np.ndarray, gyro: np.ndarray) -> bytes:
    buf = io.StringIO()
    buf.write("time,gx,gy,gz\n")
    np.savetxt(buf, np.column_stack([t, gyro]), delimiter=",", fmt="%.6f")
    return buf.getvalue().encode()


def test_csv_issue_example_300_s_hole():
    """The issue's example: 200,000 samples at 100 Hz, 30,000 (300 s) missing."""
    n, fs = 200_000, 100.0
    rng = np.random.default_rng(1)
    gyro = rng.normal(0, 0.01, (n, 3))
    keep = np.r_[0:80_000, 110_000:n]
    log = imunoise.read(_csv(np.arange(n)[keep] / fs, gyro[keep]), format="csv")
    assert len(log) == n
    assert log.fs == pytest.approx(fs, rel=1e-9)
    assert log.duration / 60 == pytest.approx(33.33, abs=0.01)
    assert _gap_list(log.gaps) == [(80_000, 30_000)]
    assert log.gaps.duration[0] == pytest.approx(300.0)
    assert log.gaps.start[0] == pytest.approx(800.0)
    assert np.isnan(log.gyro[80_000:110_000]).all()
    np.testing.assert_allclose(log.gyro[keep], gyro[keep], atol=1e-6)
    assert "30000 samples missing (15 %) in 1 gap" in str(log.issues)


def test_csv_duplicates_and_reversal_reported():
    t = np.arange(50) / 40.0
    gyro = np.arange(150.0).reshape(50, 3)
    order = np.r_[0:10, 10, 10:20, 21, 20, 22:50]  # line 11 twice, 20/21 swapped
    log = imunoise.read(_csv(t[order], gyro[order]), format="csv")
    assert len(log) == 50 and not len(log.gaps)
    assert log.issues.counts["duplicate_time"] == 1
    assert log.issues.counts["time_reversed"] == 1
    np.testing.assert_allclose(log.gyro, gyro)
    assert "duplicate_time=1" in str(log.issues) and "time_reversed=1" in str(log.issues)


def test_csv_without_time_is_one_row_per_line():
    gyro = np.zeros((20, 3))
    text = "gx,gy,gz\n" + "\n".join(",".join("0" for _ in r) for r in gyro) + "\n"
    log = imunoise.read(text.encode(), format="csv", fs=10.0)
    assert len(log) == 20 and not len(log.gaps)


# -- ROS bags --------------------------------------------------------------------------


def _stamps(n: int, period_ns: int, drop: slice, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    ns = 1_700_000_000_000_000_000 + np.arange(n) * period_ns
    ns += rng.integers(-period_ns // 10, period_ns // 10, n)  # ±10 % jitter
    keep = np.ones(n, dtype=bool)
    keep[drop] = False
    return ns, keep


@pytest.mark.parametrize("plugin", [StoragePlugin.SQLITE3, StoragePlugin.MCAP])
def test_ros2_bag_gap(tmp_path, plugin):
    n = 400
    ns, keep = _stamps(n, 25_000_000, slice(100, 140))
    store = get_typestore(Stores.ROS2_HUMBLE)
    gyro = np.random.default_rng(2).normal(0, 0.01, (n, 3))
    items = [
        (int(ns[i]), _imu(store, int(ns[i]), gyro[i], [0, 0, 9.8], [0, 0, 0, 1]))
        for i in np.flatnonzero(keep)
    ]
    _write(tmp_path / "bag", store, {"/imu": ("sensor_msgs/msg/Imu", items)}, plugin)
    log = imunoise.read(tmp_path / "bag")
    assert len(log) == n and log.fs == pytest.approx(40.0, rel=1e-3)
    assert _gap_list(log.gaps) == [(100, 40)]
    assert log.gaps.duration[0] == pytest.approx(1.0, rel=1e-3)
    np.testing.assert_array_equal(log.gyro[keep], gyro[keep])


def test_ros1_bag_gap(tmp_path):
    n = 300
    ns, keep = _stamps(n, 10_000_000, slice(50, 53), seed=3)
    keep[200] = False
    store = get_typestore(Stores.ROS1_NOETIC)
    t = store.types
    imu_type = "sensor_msgs/msg/Imu"
    V, Q = t["geometry_msgs/msg/Vector3"], t["geometry_msgs/msg/Quaternion"]
    path = tmp_path / "imu.bag"
    with Writer1(path) as writer:
        conn = writer.add_connection("/imu", imu_type, typestore=store)
        for k, i in enumerate(np.flatnonzero(keep)):
            stamp = t["builtin_interfaces/msg/Time"](
                sec=int(ns[i]) // 10**9, nanosec=int(ns[i]) % 10**9
            )
            msg = t[imu_type](
                header=t["std_msgs/msg/Header"](seq=k, stamp=stamp, frame_id="imu"),
                orientation=Q(x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=np.r_[-1.0, np.zeros(8)],
                angular_velocity=V(x=float(i), y=0.0, z=0.0),
                angular_velocity_covariance=np.zeros(9),
                linear_acceleration=V(x=0.0, y=0.0, z=9.8),
                linear_acceleration_covariance=np.zeros(9),
            )
            writer.write(conn, int(ns[i]) + 1000, store.serialize_ros1(msg, imu_type))
    log = imunoise.read(path)
    assert len(log) == n and log.fs == pytest.approx(100.0, rel=1e-3)
    assert _gap_list(log.gaps) == [(50, 3), (200, 1)]
    np.testing.assert_array_equal(log.gyro[keep, 0], np.flatnonzero(keep))


def test_real_mcap_jitter_no_false_gaps():
    log = imunoise.read(DATA / "vn100-ros" / "11sec_motion_0.mcap")
    assert not len(log.gaps) and log.issues.samples_missing == 0
    assert log.fs == pytest.approx(40.0, rel=1e-3)


@pytest.mark.skipif(not ROS1_REAL.exists(), reason="../shared/data (unlicensed ROS 1 bag) absent")
def test_real_ros1_bag_jitter_no_false_gaps():
    """±2 ms of jitter at 40 Hz (2,732 messages over 68.5 s): no gap, no duplicate."""
    log = imunoise.read(ROS1_REAL)
    assert len(log) == 2732 and not len(log.gaps)
    assert log.issues.counts["duplicate_time"] == 0
    assert log.fs == pytest.approx(40.0, rel=1e-3)


# -- VectorNav -------------------------------------------------------------------------


def _ymr_lines(n: int) -> list[str]:
    rows = np.zeros((n, 12))
    rows[:, 9] = np.arange(n) * 1e-3  # gyro x counts the samples
    return [ymr(r) for r in rows]


def test_vn_ascii_damaged_sentences_are_missing_samples_in_place():
    lines = _ymr_lines(30)
    lines[5] = ymr(np.zeros(12), bad_checksum=True)
    lines[12] = lines[12][:40]  # cut short
    lines[13] = "$VNYMR,1,2*XX"  # wrong field count, no checksum
    lines[20] = "$VNXYZ,1,2*XX"  # a message of another kind: not a sample of this stream
    data = ("\r\n".join(lines) + "\r\n").encode()
    log = imunoise.read(data, fs=40.0)
    assert len(log) == 29  # 30 lines, the unknown one is not a sample
    assert _gap_list(log.gaps) == [(5, 1), (12, 2)]
    gx = log.gyro[:, 0]
    assert np.isnan(gx[[5, 12, 13]]).all()
    good = np.r_[0:5, 6:12, 14:20, 21:30]  # line index of every good sentence
    np.testing.assert_allclose(gx[np.isfinite(gx)], good * 1e-3, atol=1e-6)
    assert log.issues.samples_missing == 3
    # a damaged first or last sentence is the capture's edge, not a gap
    edge = ("\r\n".join([lines[0][:30], *_ymr_lines(5), "$VNYMR,+0"]) + "\r\n").encode()
    assert not len(imunoise.read(edge, fs=40.0).gaps)


def test_vn_ascii_serial_counter_places_samples():
    from imunoise.writers.vn import write_vn_ascii

    n = 50
    count = np.arange(n, dtype=float) * 2 + 1000  # a SyncOut counter, step 2
    keep = np.ones(n, dtype=bool)
    keep[[10, 30, 31]] = False
    ypr = {name: np.zeros(keep.sum()) for name in ("yaw", "pitch", "roll")}
    text = write_vn_ascii(ypr, "VNYPR", count=count[keep])
    log = imunoise.read(text, fs=40.0)
    assert len(log) == n and log.fs == 40.0
    assert _gap_list(log.gaps) == [(10, 1), (30, 2)]


def test_vn_binary_time_startup_gaps():
    from imunoise.writers.vn import write_vn_binary

    n = 200
    rng = np.random.default_rng(4)
    gyro = rng.normal(0, 0.01, (n, 3))
    t = 43.0 + np.arange(n) / 800.0
    keep = np.ones(n, dtype=bool)
    keep[[7, 8, 9, 150]] = False
    data = write_vn_binary(
        {"gyro": gyro[keep], "time": t[keep]}, {"common": ["TimeStartup", "AngularRate"]}
    )
    log = imunoise.read(data)
    assert log.format == "vn-binary" and len(log) == n
    assert log.fs == pytest.approx(800.0, rel=1e-6)
    assert _gap_list(log.gaps) == [(7, 3), (150, 1)]
    np.testing.assert_allclose(log.gyro[keep], gyro[keep], rtol=1e-6)
    np.testing.assert_allclose(log.time[keep], t[keep])


def test_vn_binary_bad_crc_without_time_is_a_missing_sample():
    from imunoise.writers.vn import write_vn_binary

    n = 20
    packets = [
        write_vn_binary({"gyro": np.full((1, 3), float(i))}, {"common": ["AngularRate"]})
        for i in range(n)
    ]
    broken = bytearray(packets[6])
    broken[10] ^= 0xFF
    packets[6] = bytes(broken)
    log = imunoise.read(b"".join(packets), format="vn-binary", fs=100.0)
    assert len(log) == n and _gap_list(log.gaps) == [(6, 1)]
    np.testing.assert_array_equal(np.isnan(log.gyro[:, 0]), np.arange(n) == 6)


# -- statistics on a gapped log (needs the gap-aware Allan core) ------------------------


def _adev_takes_nan() -> bool:
    x = np.random.default_rng(0).normal(size=64)
    x[10] = np.nan
    try:
        r = imunoise.adev(x, 1.0, taus=[1.0, 2.0])
    except ValueError:
        return False
    return bool(np.isfinite(r.dev).all())


def test_gapped_csv_adev_within_ci_of_full_record():
    if not _adev_takes_nan():
        pytest.skip("imunoise.adev does not accept NaN (missing samples) in this build")
    n, fs = 200_000, 100.0
    gyro = np.random.default_rng(5).normal(0, 0.01, (n, 1))
    keep = np.r_[0:80_000, 110_000:n]
    text = b"time,gx,gy,gz\n"
    full = imunoise.adev(gyro[:, 0], fs, taus="decade")
    rows = np.column_stack([np.arange(n) / fs, gyro, gyro, gyro])[keep]
    buf = io.StringIO()
    np.savetxt(buf, rows, delimiter=",", fmt="%.8f")
    log = imunoise.read(text + buf.getvalue().encode(), format="csv")
    gapped = imunoise.adev(log.gyro[:, 0], log.fs, taus="decade")
    np.testing.assert_allclose(gapped.taus, full.taus, rtol=1e-9)  # fs from timestamps
    short = full.taus <= 100.0  # windows that fit beside the 300 s hole
    assert np.all(gapped.dev[short] >= full.ci_low[short] * 0.9)
    assert np.all(gapped.dev[short] <= full.ci_high[short] * 1.1)


# -- command line, convert, report ------------------------------------------------------


def _gapped_csv(tmp_path, n=2000, fs=40.0, hole=slice(500, 700)):
    rng = np.random.default_rng(6)
    gyro = rng.normal(0, 0.01, (n, 3))
    keep = np.ones(n, dtype=bool)
    keep[hole] = False
    path = tmp_path / "gapped.csv"
    path.write_bytes(_csv(np.arange(n)[keep] / fs, gyro[keep]))
    return path, gyro, keep


@pytest.mark.parametrize("suffix", [".csv", ".npz", ".npy", ".parquet"])
def test_convert_keeps_grid_and_notes_the_gap(tmp_path, capsys, suffix):
    from imunoise import scale
    from imunoise.cli import main

    if suffix == ".parquet":
        pytest.importorskip("pyarrow")
    src, gyro, keep = _gapped_csv(tmp_path)
    out = tmp_path / f"out{suffix}"
    assert main(["convert", str(src), "-o", str(out)]) == 0
    _out, err = capsys.readouterr()
    notes = [ln for ln in err.splitlines() if ln.startswith("imunoise: note: ")]
    assert len(notes) == 1 and "200 samples (10 %) missing in 1 gap" in notes[0], err
    if suffix == ".csv":
        back = imunoise.read(out)
    elif suffix == ".npz":
        z = np.load(out)
        np.testing.assert_array_equal(z["valid"], keep)
        back = ImuLog.from_arrays(float(z["fs"]), gyro=np.column_stack(
            [z["gyro_x"], z["gyro_y"], z["gyro_z"]]))
    else:
        back = scale.load(out)
    assert len(back) == 2000 and _gap_list(back.gaps) == [(500, 200)]
    np.testing.assert_allclose(back.gyro[keep], gyro[keep], atol=1e-6)
    assert back.issues.counts["malformed_field"] == 0


def test_streaming_convert_of_damaged_vn_ascii_matches_read(tmp_path):
    from imunoise import scale

    lines = _ymr_lines(400)
    for k in (50, 51, 300):
        lines[k] = lines[k][:30]
    src = tmp_path / "cut.txt"
    src.write_bytes(("\r\n".join(lines) + "\r\n").encode())
    ref = imunoise.read(src, fs=40.0)
    done = scale.convert(src, tmp_path / "cols", fs=40.0, chunk_bytes=4096)
    got = scale.load(done.out)
    assert _gap_list(ref.gaps) == _gap_list(got.gaps) == [(50, 2), (300, 1)]
    assert done.issues.samples_missing == 3
    np.testing.assert_array_equal(got.gyro, ref.gyro)


def test_report_shows_gaps(tmp_path):
    if not _adev_takes_nan():
        pytest.skip("imunoise.adev does not accept NaN (missing samples) in this build")
    from imunoise import report

    n = 24_000
    gyro = np.random.default_rng(7).normal(0, 1e-3, (n, 3))
    gyro[10_000:11_000] = np.nan
    accel = np.random.default_rng(8).normal(0, 1e-2, (n, 3))
    accel[10_000:11_000] = np.nan
    log = ImuLog.from_arrays(40.0, gyro=gyro, accel=accel, source="<gapped>")
    rep = report.build(log, None, tmp_path, progress=False, spec=None)
    md = rep.markdown.read_text()
    assert "1000 (4.17 %) in 1 gap" in md
    assert "**Warning**: 4.17 % of the log is missing" in md
    assert "Largest gaps" in md and "| 250 | 25 | 1000 |" in md
