"""Where the test data are: the repository's tests/data and, when present, ../shared."""

import pathlib

import pytest

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"
SHARED = pathlib.Path(__file__).resolve().parents[3] / "shared"


def shared_file(relative: str) -> pathlib.Path:
    """A file from ../shared (not redistributable); skips the test when absent."""
    path = SHARED / relative
    if not path.exists():
        pytest.skip(f"{relative} not available (../shared is not part of the repository)")
    return path
