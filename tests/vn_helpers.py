"""Test helpers shared by the CSV and bag reader tests: VN parser choice, sentence maker."""

from __future__ import annotations

import importlib.util
from functools import reduce

import _fake_vn
import pytest

#: Decoded sentence values may differ from Python's correctly rounded float() by an ulp
#: or two when a fast decimal parser is used.
VN_RTOL = 1e-15


def have_real_vn() -> bool:
    try:
        return importlib.util.find_spec("imunoise.readers.vn") is not None
    except ImportError:
        return False


@pytest.fixture(params=["stand-in", "real"])
def vn_parser(request, monkeypatch):
    """Run a test with the $VNYMR stand-in and, once it exists, with the real VN parser."""
    if request.param == "real":
        if not have_real_vn():
            pytest.skip("imunoise.readers.vn (the VN ASCII parser) is not in this build yet")
        return "real"
    import imunoise.readers._sentences as sentences

    def fake(data, *, strict, source):
        return _fake_vn.parse_vn_sentences(data, strict=strict, fs=1.0, source=source)

    monkeypatch.setattr(sentences, "parse_sentences", fake)
    return "stand-in"


def ymr(values, *, bad_checksum: bool = False) -> str:
    """A $VNYMR sentence with its 8-bit XOR checksum (the spec's section 2)."""
    body = "VNYMR," + ",".join(f"{v:+.6f}" for v in values)
    check = reduce(lambda a, b: a ^ b, body.encode(), 0) ^ (0x5A if bad_checksum else 0)
    return f"${body}*{check:02X}"


def ymr_fields(sentence: str) -> list[float]:
    """The 12 numbers of a $VNYMR sentence, read with nothing but str.split."""
    return [float(f) for f in sentence.split("*")[0].split(",")[1:]]
