"""The warning for taus that gaps cost says what limited them and what to pass."""

import imunoise
import numpy as np
import pytest
from helpers.signals import noise


def test_taus_dropped_for_gaps_name_the_runs_and_the_arguments():
    y = noise("white", 2000, seed=4)
    y[::100] = np.nan  # gap-free runs of 99 samples in a record of 2000
    with pytest.warns(UserWarning) as said:
        r = imunoise.adev(y, 10.0, taus=[0.5, 4.0, 60.0])
    text = str(said[0].message)
    assert list(r.m) == [5, 40]
    assert text == (
        "1 of 3 taus dropped: the missing samples (NaN) of x split it into gap-free runs "
        "of at most 9.9 s (99 samples), too short for 2 adev terms beyond tau = 4 s "
        "(the record's length would allow 60 s); ask taus up to that, or pass "
        "gaps='splice' to join the runs")
    assert "the gaps in x" not in text


def test_longest_valid_run_takes_the_best_channel():
    from imunoise.allan import longest_valid_run

    x = np.zeros((10, 2))
    x[[2, 7], 0] = np.nan
    x[[4], 1] = np.nan
    assert longest_valid_run(x) == 5  # channel 1: rows 5-9
    assert longest_valid_run(np.zeros((4, 1))) == 4
