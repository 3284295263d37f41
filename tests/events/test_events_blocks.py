"""The event search read a block at a time (imunoise._support.blocks): the same events and the
same numbers, bit for bit, whatever the block size, for events that straddle a block's
edge, and the block-wise reductions equal their whole-array definitions."""

import imunoise
import numpy as np
import pytest
from imunoise._analysis import events as _events
from imunoise._support import blocks as _blocks

FS = 100.0
EDGE = 3 * 997  # a block edge when blocks are 997 rows


def record(gaps: bool) -> np.ndarray:
    """Three channels of coloured noise with a burst, a shock inside a vibration and
    spikes across the row EDGE (and the 4096-row edges), missing runs with ``gaps``."""
    rng = np.random.default_rng(11)
    n = 40_000
    x = rng.standard_normal((n, 3))
    x[1:, 2] += 0.7 * x[:-1, 2]  # a correlated channel: its energy law and whitening
    t = np.arange(600) / FS
    x[EDGE - 300:EDGE + 300, 0] += 4 * np.exp(-t / 3) * np.sin(2 * np.pi * 12 * t)
    vib = np.arange(4096 - 1500, 4096 + 1500)  # a vibration across another edge …
    x[vib, 1] += 1.5 * np.sin(2 * np.pi * 7 * vib / FS)
    x[4090:4110, 1] += 25 * rng.standard_normal(20)  # … with a shock inside, on the edge
    x[EDGE, 2] += 15  # a spike on the edge, one just before it
    x[2 * 997 - 1, 2] -= 12
    x[8191, 0] += 14
    if gaps:
        for a in (EDGE - 5, 12_000, 20_479):
            x[a:a + 7, 0] = np.nan
        x[:30, 2] = np.nan
    return x


def found(x: np.ndarray):
    ev = imunoise.events(x, FS)
    return ev, ev.rms_ratio(x)


@pytest.mark.parametrize("gaps", [False, True])
@pytest.mark.parametrize("block", [997, 64, 4096])
def test_events_across_block_edges_are_those_of_the_whole_channel(monkeypatch, gaps, block):
    x = record(gaps)
    monkeypatch.setattr(_blocks, "SERIES_BLOCK", len(x))  # one block: the whole channel
    whole, whole_rms = found(x)
    # the events this test is about were found, across the edges
    assert any(a < EDGE < b for a, b in zip(whole.start_index, whole.end_index, strict=True))
    assert EDGE in whole.start_index or any(
        a <= EDGE < b for a, b in zip(whole.start_index, whole.end_index, strict=True))
    assert (whole.within >= 0).any()  # the shock inside the vibration
    monkeypatch.setattr(_blocks, "SERIES_BLOCK", block)
    blocked, blocked_rms = found(x)
    for name in ("start_index", "end_index", "peak", "sigma"):
        np.testing.assert_array_equal(getattr(blocked, name), getattr(whole, name), err_msg=name)
    assert blocked.kind == whole.kind and blocked.channels == whole.channels
    assert blocked.energy_threshold == whole.energy_threshold
    np.testing.assert_array_equal(blocked_rms, whole_rms)


def test_running_sums_at_rows_are_the_whole_cumsum(monkeypatch):
    rng = np.random.default_rng(3)
    x = rng.standard_normal(10_000) * 1e3 + 1e6  # large sums: any other order rounds apart
    whole = np.concatenate(([0.0], np.cumsum(x)))
    rows = np.unique(rng.integers(0, len(x) + 1, 500))
    monkeypatch.setattr(_blocks, "SERIES_BLOCK", 333)
    np.testing.assert_array_equal(_blocks.running_sums_at(_blocks.view(x), len(x), rows),
                                  whole[rows])


def test_lag_products_and_gather_are_the_whole_arrays(monkeypatch):
    rng = np.random.default_rng(4)
    x = rng.standard_normal(50_000)
    keep = rng.random(len(x)) < 0.7
    x[rng.integers(0, len(x), 300)] = np.nan
    clean = np.nan_to_num(x)
    monkeypatch.setattr(_blocks, "SERIES_BLOCK", len(x))
    lags_whole = _blocks.lag_products(_blocks.view(clean), len(x), 200)
    monkeypatch.setattr(_blocks, "SERIES_BLOCK", 777)
    np.testing.assert_array_equal(_blocks.lag_products(_blocks.view(clean), len(x), 200),
                                  lags_whole)
    direct = np.array([np.dot(clean[:len(x) - k], clean[k:]) for k in (0, 1, 57, 199)])
    np.testing.assert_allclose(lags_whole[[0, 1, 57, 199]], direct, rtol=1e-9, atol=1e-8)
    np.testing.assert_array_equal(_blocks.gather(_blocks.view(x), len(x), keep),
                                  x[keep][np.isfinite(x[keep])])


def test_whitening_a_block_at_a_time_is_one_filter_over_the_record(monkeypatch):
    rng = np.random.default_rng(5)
    z = rng.standard_normal(20_000)
    z[1:] += 0.6 * z[:-1]
    rho = np.array([1.0, 0.44, 0.2, 0.1, 0.05])
    isolated = np.zeros(len(z), dtype=bool)
    monkeypatch.setattr(_blocks, "SERIES_BLOCK", len(z))
    whole = _events._whiten(_blocks.view(z), len(z), None, rho, 5.0, isolated)
    monkeypatch.setattr(_blocks, "SERIES_BLOCK", 100)
    np.testing.assert_array_equal(
        _events._whiten(_blocks.view(z), len(z), None, rho, 5.0, isolated), whole)


@pytest.mark.parametrize("gaps", [False, True])
def test_search_baselines_give_rms_ratio_without_the_medians_again(gaps):
    """The report's path: the events search's baselines read the standardised samples
    again, and give Events.rms_ratio's numbers bit for bit; the events are events()'s."""
    x = record(gaps)
    ev, rms = found(x)
    searched, baselines = _events.search(x, FS)
    for name in ("start_index", "end_index", "peak", "sigma"):
        np.testing.assert_array_equal(getattr(searched, name), getattr(ev, name), err_msg=name)
    assert searched.kind == ev.kind and searched.channels == ev.channels
    np.testing.assert_array_equal(_events.rms_ratio(searched, x, baselines), rms)
    with pytest.raises(ValueError, match="record the events"):
        _events.rms_ratio(searched, x[:, :2], baselines)


def test_a_pass_whose_quiet_part_did_not_change_reuses_the_law(monkeypatch):
    """The last pass's energy law is the middle pass's when their quiet samples are
    the same: computed once (the same events as computing it again)."""
    x = record(False)
    calls = []
    law = _events._energy_law
    monkeypatch.setattr(_events, "_energy_law",
                        lambda z, n, w: calls.append(n) or law(z, n, w))
    reused = imunoise.events(x, FS)
    n_reused = len(calls)
    monkeypatch.setattr(_events, "_same_mask", lambda a, b: False)
    calls.clear()
    again = imunoise.events(x, FS)
    assert n_reused < len(calls)
    for name in ("start_index", "end_index", "peak", "sigma"):
        np.testing.assert_array_equal(getattr(reused, name), getattr(again, name))
