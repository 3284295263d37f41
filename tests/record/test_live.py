"""The recorder's live view: its ADEV is an AllanStream fed the samples since the last
refresh, dropped samples fed as a gap, restarted when the rate becomes known."""

from __future__ import annotations

import imunoise
import numpy as np
from imunoise.recording.live import LiveView

FS = 100.0


def test_live_adev_follows_the_stream_with_its_gaps_and_its_rate():
    n = 6000
    gyro = imunoise.simulate(n, FS, N=1e-3, K=1e-5, channels=3, seed=3)
    keep = np.ones(n, dtype=bool)
    keep[2000:2150] = False  # a dropout: 150 samples never sent
    keep[4321] = False
    log = imunoise.ImuLog.from_arrays(FS, gyro=gyro[keep], time=(np.arange(n) / FS)[keep])
    data = imunoise.write_vn_binary(log)
    # the configured rate is wrong: the timestamps correct it at the first refreshes
    live = LiveView(rates={"binary": 40.0}, target=None, show=False)
    snaps = []
    packet = len(data) // len(log)
    live._parse(data[:packet])  # one sample: no timestamp step yet
    snaps.append(live.snapshot())
    for chunk in np.array_split(np.frombuffer(data[packet:], dtype=np.uint8), 37):
        live._parse(chunk.tobytes())  # what the view's thread does with a chunk
        snaps.append(live.snapshot())
    final = live.close()
    assert snaps[0].fs == 40.0 and snaps[0].adev is None
    assert abs(final.fs - FS) < 1e-9 and final.dropped == 151
    read = imunoise.read(data)
    assert read.gaps.total == 151
    whole = imunoise.adev(read.gyro, read.fs, gaps="skip")
    k = len(final.adev.taus)
    assert k >= len(whole.taus) - 1 and final.adev.missing[0] == 151
    np.testing.assert_array_equal(final.adev.n, whole.n[:k])
    np.testing.assert_allclose(final.adev.dev, whole.dev[:k], rtol=1e-9)
    np.testing.assert_allclose(final.adev.taus, whole.taus[:k], rtol=1e-9)
    # fed in pieces: the stream holds every sample once, the gap's rows included
    assert live._stream.n_samples == n
