"""Damaged records cannot make the reader allocate unboundedly many missing rows."""

import imunoise
import pytest
from imunoise.readers.grid import MAX_GRID_RATIO, TimeGrid


def _log(good_each_side: int, damaged: int) -> bytes:
    from imunoise.cli import bundled_log

    lines = bundled_log().read_bytes().splitlines(keepends=True)
    good = b"".join(lines[:2 * good_each_side])
    half = len(b"".join(lines[:good_each_side]))
    return good[:half] + b"$VNYMR," * damaged + b"\r\n" + good[half:]


def test_a_run_of_bare_headers_is_refused_beyond_the_bound():
    # 73 MB of "$VNYMR," became 10.5 M missing rows (1.37 GB); the same at a small scale
    limit = (MAX_GRID_RATIO - 1) * 20
    log = imunoise.read(_log(10, limit), format="vn-ascii", fs=40.0)
    assert log.gaps.total == limit  # at the bound: every damaged record is a gap
    with pytest.raises(ValueError, match=rf"{limit + 1} damaged records among 20 good ones.*"
                                         rf"more than {MAX_GRID_RATIO}x"):
        imunoise.read(_log(10, limit + 1), format="vn-ascii", fs=40.0)


def test_from_missing_bound():
    assert TimeGrid.from_missing(2, [1] * (MAX_GRID_RATIO * 2 - 2)).n == MAX_GRID_RATIO * 2
    with pytest.raises(ValueError, match="not a sample sequence"):
        TimeGrid.from_missing(2, [1] * (MAX_GRID_RATIO * 2 - 1))
