"""tools/check_wheel.py refuses a wheel whose file name lacks the platform tag a release
publishes it under (a manylinux2014 wheel must say manylinux_2_17)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))
import check_wheel  # noqa: E402

NAME = "imunoise-0.1.0-cp310-abi3-manylinux2014_x86_64.manylinux_2_17_x86_64.whl"


def test_a_wheel_for_a_newer_glibc_is_refused():
    with pytest.raises(SystemExit, match="is not tagged manylinux_2_17_x86_64"):
        check_wheel.check_tag(Path("imunoise-0.1.0-cp310-abi3-manylinux_2_35_x86_64.whl"),
                              "manylinux_2_17_x86_64")


def test_the_tag_is_one_of_the_compressed_tags(monkeypatch, capsys):
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "auditwheel" else real(name, *a))
    check_wheel.check_tag(Path(NAME), "manylinux_2_17_x86_64")
    assert "tag ok: manylinux_2_17_x86_64 (file name; auditwheel not installed)" in \
        capsys.readouterr().out
    with pytest.raises(SystemExit):  # a prefix of a tag is not the tag
        check_wheel.check_tag(Path(NAME), "manylinux_2_17")
