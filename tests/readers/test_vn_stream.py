"""One streaming parse fed piece by piece equals one parse of the whole stream."""

from __future__ import annotations

import imunoise
import numpy as np
import pytest
from imunoise._core import vn as _core_vn
from imunoise._simulation.log import still_log
from imunoise.errors import ParseError


def _damaged() -> bytes:
    log = still_log(0.02, 40.0, seed=5)
    ascii_part = bytearray(imunoise.write_vn_ascii(log, "VNYMR"))
    star = ascii_part.index(b"*", 5000)  # one bad checksum: another first hex digit
    ascii_part[star + 1] = ord("0") if ascii_part[star + 1] != ord("0") else ord("1")
    binary_part = imunoise.write_vn_binary(log)
    return bytes(ascii_part[:40_000]) + b"noise" + binary_part + bytes(ascii_part[40_000:-30])


# Pieces shorter and longer than the 64 KiB that finish a cut record, each as bytes
# and as a view of a reused buffer (how convert feeds them).
@pytest.mark.parametrize("buffer", [bytes, lambda b: memoryview(bytearray(b))])
@pytest.mark.parametrize("piece", [1000, 4096 + 17, 70_001, 150_000, 1 << 20])
def test_pieces_add_up_to_the_whole(piece, buffer):
    data = _damaged()
    whole = _core_vn.parse_vn(data)
    stream = _core_vn.VnStream()
    rows: dict[str, dict[str, list[np.ndarray]]] = {}

    def take(part) -> None:
        for name, cols in part.tables.items():
            for col, values in cols.items():
                rows.setdefault(name, {}).setdefault(col, []).append(values)

    for start in range(0, len(data), piece):
        take(stream.feed(buffer(data[start : start + piece])))
    summary = stream.finish()
    take(summary)
    for name, cols in whole.tables.items():
        for col, values in cols.items():
            got = np.concatenate(rows[name][col])
            np.testing.assert_array_equal(got, values, err_msg=f"{name}.{col}")
    assert summary.issues == whole.issues and summary.first == whole.first
    assert summary.messages == whole.messages
    assert summary.format == whole.format
    for attr in ("bytes_total", "bytes_parsed", "bytes_in_bad_records", "bytes_skipped",
                 "ascii_records", "binary_records"):
        assert getattr(summary, attr) == getattr(whole, attr), attr


def test_strict_stream_raises_parse_error_with_the_absolute_location():
    data = _damaged()
    want = _core_vn.parse_vn(data).first["bad_checksum"][0]
    stream = _core_vn.VnStream(strict=True)
    with pytest.raises(ParseError) as raised:
        for start in range(0, len(data), 1000):
            stream.feed(data[start : start + 1000])
        stream.finish()
    assert (raised.value.offset, raised.value.line) == want
    assert raised.value.kind == "bad_checksum"


def test_feed_takes_bytes_or_a_contiguous_byte_buffer():
    stream = _core_vn.VnStream()
    with pytest.raises(TypeError, match="data must be bytes or a buffer of bytes; got str"):
        stream.feed("$VNYMR")
    with pytest.raises(ValueError, match="C-contiguous"):
        stream.feed(memoryview(bytearray(b"$VNYMR,1,2*00\r\n" * 4))[::2])


def test_finish_once():
    stream = _core_vn.VnStream()
    stream.finish()
    with pytest.raises(ValueError, match="finish"):
        stream.finish()
    with pytest.raises(ValueError, match="feed"):
        stream.feed(b"")


def test_missing_file_and_result_attributes(tmp_path):
    with pytest.raises(FileNotFoundError):
        _core_vn.parse_vn(str(tmp_path / "absent.bin"))
    result = _core_vn.parse_vn(b"$VNYPR,+010.071,+000.278,-002.026*60\r\n")
    assert result.format == "vn-ascii" and result.messages == {"VNYPR": 1}
    assert set(result.issues) == set(_core_vn.ISSUE_KINDS)


def test_rows_of_a_dropped_piece_make_room_for_the_next_and_kept_ones_stay():
    # A piece's arrays, once dropped, give their buffer back for the next piece's
    # rows (convert's pieces reuse memory); arrays still held are never written.
    data = _damaged()
    whole = _core_vn.parse_vn(data)
    stream = _core_vn.VnStream()
    kept = []  # every other piece's arrays, held; their copies to compare
    rows: dict[str, dict[str, list[np.ndarray]]] = {}
    piece = 20_000
    seen: set[int] = set()
    reused = 0
    for k, start in enumerate(range(0, len(data), piece)):
        part = stream.feed(data[start : start + piece])
        for name, cols in part.tables.items():
            at = next(iter(cols.values())).__array_interface__["data"][0]
            reused += at in seen and len(next(iter(cols.values()))) > 0
            seen.add(at)
            for col, values in cols.items():
                rows.setdefault(name, {}).setdefault(col, []).append(values.copy())
                if k % 2:
                    kept.append((values, values.copy()))
        del part, cols, values
    summary = stream.finish()
    for name, cols in summary.tables.items():
        for col, values in cols.items():
            rows.setdefault(name, {}).setdefault(col, []).append(values)
    for name, cols in whole.tables.items():
        for col, values in cols.items():
            np.testing.assert_array_equal(np.concatenate(rows[name][col]), values,
                                          err_msg=f"{name}.{col}")
    for held, copy in kept:
        np.testing.assert_array_equal(held, copy)
    assert reused, "no piece reused the buffer of a dropped one"
