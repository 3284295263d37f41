"""Several logs of one mount on one time grid: the common span, each log's own samples
at the nearest common row (none interpolated), and what each log lost, counted."""

from __future__ import annotations

import imunoise
import numpy as np
import pytest
from helpers.mount import mount_logs

FS = 50.0
N = 20_000
WHITE = (0.01, 0.02, 0.03)


def test_shared_clock_keeps_each_log_own_samples_on_the_common_rows():
    starts, ends = (0, 300, 1234), (N - 700, N, N - 50)
    logs = mount_logs(N, FS, WHITE, starts=starts, ends=ends, jitter=0.3, seed=1)
    gyro = logs[1].gyro.copy()
    gyro[5000:5040] = np.nan  # a dropout of log 1 inside the span
    logs[1] = imunoise.ImuLog.from_arrays(FS, gyro=gyro, time=logs[1].time, source="<one>")
    al = imunoise.align(logs)
    first, last = max(starts), min(ends) - 1
    assert al.n_samples == last - first + 1 and al.fs == FS and len(al) == 3
    np.testing.assert_array_equal(al.before, [first - s for s in starts])
    np.testing.assert_array_equal(al.after, [e - 1 - last for e in ends])
    np.testing.assert_array_equal(al.doubled, [0, 0, 0])
    np.testing.assert_array_equal(al.missing, [0, 40, 0])
    np.testing.assert_array_equal(al.dropped, al.before + al.after)
    # row k of the common grid holds sample first + k of every sensor, untouched
    for log, aligned, s in zip(logs, al, starts, strict=True):
        np.testing.assert_array_equal(aligned.gyro, log.gyro[first - s:last + 1 - s])
    assert len(al[1].gaps) == 1 and al[1].gaps.total == 40
    np.testing.assert_allclose(al.offsets, [(s - starts[0]) / FS for s in starts], atol=0.02 / FS)
    assert np.all(np.abs(al.phase) < 0.05 / FS)
    np.testing.assert_allclose(np.diff(al[2].time), 1 / FS)
    assert np.all(np.isnan(al.correlation))
    assert "3 logs at 50 Hz" in repr(al) and "cut before 1234/934/0" in repr(al)


def test_own_clocks_are_lined_up_on_the_motion():
    starts, ends = (500, 0, 2000), (N, N - 1000, N - 10)
    offsets = (0.0, 1234.5678, 86_400.25)  # each clock from its own power-on
    logs = mount_logs(N, FS, WHITE, starts=starts, ends=ends, clock_offsets=offsets, seed=2)
    with pytest.raises(imunoise.ImunoiseValueError, match="logs must overlap"):
        imunoise.align(logs)  # the timestamps say they never met
    al = imunoise.align(logs, clock="motion")
    np.testing.assert_allclose(al.offsets, [(s - starts[0]) / FS for s in starts],
                               atol=0.05 / FS)
    assert np.all(al.correlation > 0.99)
    first = max(starts)
    for log, aligned, s in zip(logs, al, starts, strict=True):
        np.testing.assert_array_equal(aligned.gyro[:100], log.gyro[first - s:first - s + 100])


def test_a_log_off_the_reference_rate_loses_samples_counted():
    logs = mount_logs(N, FS, WHITE[:2], starts=(0, 0), ends=(N, N), seed=3)
    fast = 1.0 + 2e-4  # 200 ppm: its clock gains a sample every 5000
    quick = imunoise.ImuLog.from_arrays(FS * fast, gyro=logs[1].gyro, time=logs[1].time / fast)
    al = imunoise.align([logs[0], quick])
    assert al.doubled[1] == pytest.approx(N * 2e-4, abs=2) and al.missing[1] == 0
    slow = imunoise.ImuLog.from_arrays(FS / fast, gyro=logs[1].gyro, time=logs[1].time * fast)
    al = imunoise.align([logs[0], slow])
    assert al.missing[1] == pytest.approx(N * 2e-4, abs=2) and al.doubled[1] == 0
    off = imunoise.ImuLog.from_arrays(FS * 1.01, gyro=logs[1].gyro, time=logs[1].time / 1.01)
    with pytest.raises(imunoise.ImunoiseValueError,
                       match=r"logs\[1\]'s rate 50.5 Hz differs from logs\[0\]'s 50 Hz by "
                             r"0.01 .*more than tolerance=0.001"):
        imunoise.align([logs[0], off])
    assert imunoise.align([logs[0], off], tolerance=0.02).doubled[1] > 150


def test_files_are_read_and_aligned(tmp_path):
    logs = mount_logs(4000, FS, WHITE[:2], starts=(0, 100), ends=(4000, 3900), seed=4,
                      clock_offsets=(10.0, 10.0))
    paths = [tmp_path / f"s{i}.bin" for i in range(2)]
    for log, path in zip(logs, paths, strict=True):
        imunoise.write_vn_binary(log, path=path)
    al = imunoise.align(paths)
    assert al.n_samples == 3800 and list(al.before) == [100, 0]
    np.testing.assert_allclose(al[1].gyro, logs[1].gyro[:3800], rtol=1e-6)


def test_bad_inputs_are_named():
    logs = mount_logs(2000, FS, WHITE[:2], starts=(0, 0), ends=(2000, 2000), seed=5)
    with pytest.raises(imunoise.ImunoiseValueError, match="at least 2 logs; got 1"):
        imunoise.align(logs[:1])
    with pytest.raises(imunoise.ImunoiseTypeError, match="a sequence of logs"):
        imunoise.align(logs[0])
    with pytest.raises(imunoise.ImunoiseValueError, match="clock must be one of"):
        imunoise.align(logs, clock="gps")
    untimed = imunoise.ImuLog.from_arrays(FS, gyro=logs[1].gyro)
    with pytest.raises(imunoise.ImunoiseValueError, match=r"logs\[1\] .* has no timestamps"):
        imunoise.align([logs[0], untimed])
    still = mount_logs(2000, FS, WHITE[:2], starts=(0, 0), ends=(2000, 2000), motion=0.0,
                       seed=6)
    with pytest.raises(imunoise.ImunoiseValueError, match=r"does not follow logs\[0\]'s"):
        imunoise.align(still, clock="motion")
    with pytest.raises(imunoise.ImunoiseValueError, match=r"logs\[0\] has no 'accel'"):
        imunoise.align(logs, clock="motion", channel="accel")
    with pytest.raises(imunoise.ImunoiseValueError, match="tolerance"):
        imunoise.align(logs, tolerance=0)
