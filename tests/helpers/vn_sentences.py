"""Test helpers shared by the CSV and bag reader tests: a $VNYMR sentence maker."""

from __future__ import annotations

from functools import reduce

#: Decoded sentence values may differ from Python's correctly rounded float() by an ulp
#: or two when a fast decimal parser is used.
VN_RTOL = 1e-15


def ymr(values, *, bad_checksum: bool = False) -> str:
    """A $VNYMR sentence with its 8-bit XOR checksum (the spec's section 2)."""
    body = "VNYMR," + ",".join(f"{v:+.6f}" for v in values)
    check = reduce(lambda a, b: a ^ b, body.encode(), 0) ^ (0x5A if bad_checksum else 0)
    return f"${body}*{check:02X}"


def ymr_fields(sentence: str) -> list[float]:
    """The 12 numbers of a $VNYMR sentence, read with nothing but str.split."""
    return [float(f) for f in sentence.split("*")[0].split(",")[1:]]
