"""A minimal $VNYMR-only stand-in for the VN parser, for tests of the container logic.

It checks the 8-bit checksum and decodes the 12 VNYMR fields; anything else on a line
is a bad record. The real parser (imunoise.readers.vn) is tested on its own; these tests
only check how the CSV and bag readers line samples up with rows and messages.
"""

from __future__ import annotations

import re
from functools import reduce

import numpy as np
from imunoise.readers.log import ImuLog, ParseIssues

_SENTENCE = re.compile(rb"\$(VNYMR,[^*$]*)\*([0-9A-Fa-f]{2})")


def parse_vn_sentences(data: bytes, *, strict=False, fs=None, source="<bytes>") -> ImuLog:
    rows, counts, first = [], {}, {}

    def bad(kind, line_no, reason):
        if strict:
            raise ValueError(f"{source}: line {line_no}: {reason}")
        counts[kind] = counts.get(kind, 0) + 1
        first.setdefault(kind, []).append(line_no)

    for line_no, line in enumerate(data.split(b"\n"), start=1):
        for m in _SENTENCE.finditer(line):
            body, check = m.group(1), int(m.group(2), 16)
            if reduce(lambda a, b: a ^ b, body, 0) != check:
                bad("bad_checksum", line_no, "checksum mismatch")
                continue
            fields = body.split(b",")[1:]
            try:
                values = [float(f) for f in fields]
            except ValueError:
                values = []
            if len(values) != 12:
                bad("malformed_field", line_no, "VNYMR needs 12 numbers")
                continue
            rows.append(values)
    a = np.asarray(rows, dtype=np.float64).reshape(-1, 12)
    return ImuLog(
        fs=fs or 40.0,
        source=source,
        format="vn-ascii",
        issues=ParseIssues(counts=counts, first=first),
        ypr=a[:, 0:3],
        mag=a[:, 3:6],
        accel=a[:, 6:9],
        gyro=a[:, 9:12],
        messages={"VNYMR": len(a)},
    )
