"""Every instruction-set level of the VN reader gives the scalar level's answer.

From AVX2 on, sentences laid out like the last one of their type (the sensor's
fixed-width fields) are checked and decoded in vector registers; the scalar
level is the reference. Streams of several MB (parsed in pieces on all cores)
with the damage a serial line produces are read at every level this CPU has
(``IMUNOISE_SIMD`` pins the same levels) and compared value for value, bit for
bit, with every count, first location, damaged-row index and byte total.
"""

from __future__ import annotations

import numpy as np
import pytest
from imunoise._support import cpu as _cpu
from imunoise.readers.vn import read_vn_tables
from imunoise.writers.vn import write_vn_ascii

LEVELS = _cpu.available_levels()


def _log(n: int, seed: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    return {
        "ypr": rng.normal([100.0, -7.3, 0.7], 50.0, (n, 3)),
        "mag": rng.normal([-0.005, -0.245, 0.54], 0.5, (n, 3)),
        "accel": rng.normal([0.0, 0.0, -9.81], 3.0, (n, 3)),
        "gyro": rng.normal(0.0, 0.5, (n, 3)),
    }


def _damaged(seed: int, edits: int) -> bytes:
    """Fixed-width sentences (two message types, CRLF and LF, a width change),
    then damage: wrong checksums, bytes changed to '$', '*', ',', digits or
    0xFA, sentences cut or joined, noise with '$' inside, lines longer than a
    shape's window, a binary-looking packet."""
    rng = np.random.default_rng(seed)
    parts = [
        write_vn_ascii(_log(9000, seed), "VNYMR"),
        write_vn_ascii(_log(3000, seed + 1), "VNYMR", line_ending="\n"),
        write_vn_ascii(_log(3000, seed + 2), "VNYPR"),
        write_vn_ascii(_log(3000, seed + 3), "VNYMR", decimals=[4] * 12),
        write_vn_ascii(_log(2000, seed + 4), "VNYMR", crc=True),
    ]
    # Interleave two message types line by line in the last part.
    a = write_vn_ascii(_log(2000, seed + 5), "VNYMR").splitlines(keepends=True)
    b = write_vn_ascii(_log(2000, seed + 6), "VNYPR").splitlines(keepends=True)
    parts.append(b"".join(x + y for x, y in zip(a, b, strict=True)))
    data = bytearray(b"".join(parts))
    for _ in range(edits):
        at = int(rng.integers(len(data)))
        kind = int(rng.integers(6))
        if kind == 0:
            data[at] = int(rng.choice(list(b"$*,.+-079aX\r\n\xfa ")))
        elif kind == 1:
            del data[at : at + int(rng.integers(1, 40))]
        elif kind == 2:
            data[at:at] = b"noise $ $VN $VNYMR,+1*00 garbage\r\n"
        elif kind == 3:
            data[at:at] = b"$VNYMR" + b",+0.5" * 80 + b"*00\r\n"
        elif kind == 4:
            star = data.find(b"*", at)
            if 0 <= star < len(data) - 1:
                data[star + 1] = ord("0") if data[star + 1] != ord("0") else ord("1")
        else:
            data[at:at] = b"\xfa\x01\x09\x00" + bytes(rng.integers(0, 256, 20, dtype=np.uint8))
    return bytes(data)


def _summary(t) -> dict:
    return {
        "messages": dict(t.messages),
        "counts": dict(t.issues.counts),
        "first": {k: tuple(v) for k, v in t.issues.first.items()},
        "bytes": (t.bytes_total, t.bytes_parsed, t.bytes_in_bad_records, t.bytes_skipped),
        "records": (t.ascii_records, t.binary_records),
        "missing": {k: v.tolist() for k, v in t.missing.items()},
    }


def _assert_same(got, want, label: str) -> None:
    assert _summary(got) == _summary(want), label
    assert got.tables.keys() == want.tables.keys(), label
    for name, cols in want.tables.items():
        assert cols.keys() == got.tables[name].keys(), (label, name)
        for col, ref in cols.items():
            mine = got.tables[name][col]
            assert mine.shape == ref.shape, (label, name, col)
            # Bits, so that -0.0 and NaN padding count too.
            assert np.array_equal(mine.view(np.uint64), ref.view(np.uint64)), (label, name, col)


@pytest.mark.parametrize("seed,edits", [(1, 0), (2, 40), (3, 400), (4, 3000)])
def test_every_level_reads_a_damaged_stream_as_scalar(seed, edits, tmp_path):
    data = _damaged(seed, edits)
    assert len(data) > 2 << 20  # parsed in pieces on all cores
    path = tmp_path / "log.txt"
    path.write_bytes(data)
    with _cpu.forced("scalar"):
        want = read_vn_tables(data)
    assert want.ascii_records > 20000
    for level in LEVELS:
        with _cpu.forced(level):
            _assert_same(read_vn_tables(data), want, f"{level} bytes")
            _assert_same(read_vn_tables(path), want, f"{level} file")


def test_every_level_reads_each_cut_as_scalar():
    # The same stream ending at every byte of a few sentences: a sentence cut
    # by the end of the input, inside the window a shape reads, or after it.
    data = _damaged(5, 20)[: 3 << 20]
    end = data.rfind(b"$VNYMR", 0, len(data) - 1000)
    for cut in range(end - 3, end + 260, 7):
        with _cpu.forced("scalar"):
            want = read_vn_tables(data[:cut])
        for level in LEVELS[1:]:
            with _cpu.forced(level):
                _assert_same(read_vn_tables(data[:cut]), want, f"{level} cut {cut}")


def test_strict_mode_fails_at_the_same_record_at_every_level():
    data = _damaged(6, 30)
    with _cpu.forced("scalar"), pytest.raises(ValueError) as want:
        read_vn_tables(data, strict=True)
    for level in LEVELS[1:]:
        with _cpu.forced(level), pytest.raises(ValueError) as got:
            read_vn_tables(data, strict=True)
        assert str(got.value) == str(want.value), level
