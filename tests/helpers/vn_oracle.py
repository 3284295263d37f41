"""A plain-Python VN ASCII reader used as an independent oracle in the tests."""

from __future__ import annotations

import re
from functools import reduce

NUMBER = re.compile(rb"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")
SENTENCE = re.compile(rb"\$(VN[A-Z]{3}[ -)+-~]*?)\*([0-9A-F]{2})(?![0-9A-Fa-f])")


def xor8(body: bytes) -> int:
    return reduce(lambda a, c: a ^ c, body, 0)


def good_sentences(data: bytes, header: bytes = b"VNYMR") -> list[list[float]]:
    """Values of every sentence of `header` whose XOR-8 checksum is right."""
    rows = []
    for m in SENTENCE.finditer(data):
        body, check = m.group(1), int(m.group(2), 16)
        if xor8(body) == check and body.startswith(header + b","):
            fields = body.split(b",")[1:]
            if all(NUMBER.fullmatch(v) for v in fields):
                rows.append([float(v) for v in fields])
    return rows
