"""The fast paths of the VN reader give exactly the plain answer.

* ASCII numbers are bit-identical to Python's ``float()`` whatever their width
  (the fused fast path takes short plain decimals, the general parser the rest).
* Streams of several MB are parsed on all cores (pieces cut at newlines, or at
  good binary packets); on damaged streams every record, count and first
  location must equal what an independent oracle says, including damage that
  straddles the cuts between pieces.
"""

from __future__ import annotations

import imunoise
import numpy as np
import pytest
from helpers.vn_oracle import good_sentences, xor8
from hypothesis import given, settings
from hypothesis import strategies as st
from imunoise._core import vn as _core_vn
from imunoise.readers.vn import read_vn_tables

_DIGITS = st.text("0123456789", min_size=0, max_size=24)


@st.composite
def decimals(draw) -> str:
    sign = draw(st.sampled_from(["", "+", "-"]))
    whole, frac = draw(_DIGITS), draw(_DIGITS)
    dot = draw(st.booleans())
    if not whole and not frac:
        whole = "0"
    text = sign + whole + ("." + frac if dot else frac)
    if draw(st.integers(0, 9)) == 0:
        text += "e" + draw(st.sampled_from(["", "-", "+"])) + str(draw(st.integers(0, 300)))
    return text


def sentence(body: str) -> bytes:
    raw = body.encode()
    return b"$" + raw + b"*%02X\r\n" % xor8(raw)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(decimals(), decimals(), decimals()), min_size=1, max_size=20))
def test_numbers_are_bit_identical_to_python_float(rows):
    expect = np.array([[float(v) for v in row] for row in rows])
    finite = np.isfinite(expect).all(axis=1)
    data = b"".join(sentence("VNYPR," + ",".join(row)) for row in rows)
    t = read_vn_tables(data)
    got = t.tables["VNYPR"] if finite.any() else {}
    assert t.messages.get("VNYPR", 0) == int(finite.sum())
    # Non-finite values (1e999) are malformed fields, not numbers.
    assert t.issues.counts["malformed_field"] == int((~finite).sum())
    if finite.any():
        values = np.column_stack([got["yaw"], got["pitch"], got["roll"]])
        assert values.view(np.int64).tolist() == expect[finite].view(np.int64).tolist()


def test_long_numbers_do_not_wrap():
    # 20 digits do not fit a u64 mantissa: the general parser takes them.
    body = "VNYPR,18446744073709551617,+1844674407370955161.7,-0.12345678901234567890"
    t = read_vn_tables(sentence(body))
    assert t.tables["VNYPR"]["yaw"][0] == float("18446744073709551617")
    assert t.tables["VNYPR"]["pitch"][0] == float("1844674407370955161.7")
    assert t.tables["VNYPR"]["roll"][0] == float("-0.12345678901234567890")


def _still(n: int, fs: float, seed: int) -> imunoise.ImuLog:
    rng = np.random.default_rng(seed)
    return imunoise.ImuLog.from_arrays(
        fs,
        ypr=rng.normal([100.0, -7.3, 0.7], 0.01, (n, 3)),
        mag=rng.normal([-0.005, -0.245, 0.54], 0.001, (n, 3)),
        accel=rng.normal([0.0, 0.0, -9.81], 0.01, (n, 3)),
        gyro=rng.normal(0.0, 0.0005, (n, 3)),
        temperature=rng.normal(25.0, 0.1, n),
        pressure=rng.normal(101.3, 0.01, n),
    )


def _damaged_ascii(seed: int) -> tuple[bytes, dict]:
    """~4 MB of $VNYMR with known damage, and what the reader must report."""
    rng = np.random.default_rng(seed)
    n = 32_000
    lines = imunoise.write_vn_ascii(_still(n, 40.0, seed), "VNYMR").splitlines(keepends=True)
    out: list[bytes] = []
    expect = {"bad_checksum": [], "truncated_record": [], "bytes_skipped": []}
    skipped = 0
    bad_at = set(rng.choice(n, 7, replace=False).tolist())
    cut_at = set(rng.choice(n, 6, replace=False).tolist()) - bad_at
    noise_at = sorted(set(rng.choice(n, 3, replace=False).tolist()) - bad_at - cut_at)
    for k, line in enumerate(lines):
        if k in noise_at:
            # A run of text lines long enough to contain a cut between pieces.
            run = b"logger: no fix yet\n" * int(rng.integers(20_000, 40_000))
            expect["bytes_skipped"].append(len(out) + 1)
            out.append(run)
            skipped += len(run)
            out.extend([b""] * (run.count(b"\n") - 1))  # keep line numbers = len(out)
        if k in bad_at:
            star = line.index(b"*")
            digit = line[star + 1 : star + 2]
            line = line[: star + 1] + (b"0" if digit != b"0" else b"1") + line[star + 2 :]
            expect["bad_checksum"].append(len(out) + 1)
        elif k in cut_at:
            line = line[: len(line) // 2] + b"\r\n"
            expect["truncated_record"].append(len(out) + 1)
        out.append(line)
    data = b"".join(out)
    rows = np.array(good_sentences(data))
    return data, {"expect": expect, "skipped": skipped, "rows": rows}


@pytest.mark.parametrize("seed", [1, 2])
def test_parallel_ascii_matches_oracle(tmp_path, seed):
    data, want = _damaged_ascii(seed)
    assert len(data) > 3 << 20  # several pieces on any number of cores
    path = tmp_path / "ymr.txt"
    path.write_bytes(data)
    for source in (data, path):
        t = read_vn_tables(source)
        got = t.tables["VNYMR"]
        values = np.column_stack([got[k] for k in got])
        np.testing.assert_array_equal(values, want["rows"])
        for kind, lines in want["expect"].items():
            count = want["skipped"] if kind == "bytes_skipped" else len(lines)
            assert t.issues.counts[kind] == count
            assert t.issues.first[kind] == tuple(sorted(lines)[:5]), kind
        assert t.bytes_parsed + t.bytes_in_bad_records + t.bytes_skipped == len(data)


def test_parallel_binary_matches_written_values(tmp_path):
    n = 60_000
    log = _still(n, 800.0, 3)
    data = bytearray(imunoise.write_vn_binary(log))
    size = len(data) // n
    rng = np.random.default_rng(3)
    damaged = np.sort(rng.choice(n, 9, replace=False))
    for k in damaged:
        data[k * size + 10] ^= 0x04  # a payload byte: the CRC fails
    data = bytes(data)
    path = tmp_path / "cap.bin"
    path.write_bytes(data)
    keep = np.setdiff1d(np.arange(n), damaged)
    for source in (data, path):
        got = imunoise.read(source)
        # a lost packet is a NaN row on the TimeStartup grid
        assert len(got) == n and list(got.gaps.index) == list(damaged)
        np.testing.assert_array_equal(got.gyro[keep], log.gyro[keep].astype(np.float32))
        assert np.isnan(got.gyro[damaged]).all()
        np.testing.assert_allclose(got.time, np.arange(n) / 800.0, rtol=0, atol=1e-9)
        assert got.issues.counts["bad_checksum"] == len(damaged)
        assert got.issues.counts["bytes_skipped"] == len(damaged) * size
        assert got.issues.first["bad_checksum"] == tuple(int(k) * size for k in damaged[:5])
        assert got.issues.first["bytes_skipped"] == tuple(int(k) * size for k in damaged[:5])


def test_channels_are_views_of_one_table():
    data = imunoise.write_vn_ascii(_still(500, 40.0, 4), "VNYMR")
    log = imunoise.read(data, fs=40.0)
    t = _core_vn.parse_vn(data, False, None)["tables"]["VNYMR"]
    # Rows of the 12-column VNYMR matrix, not a stacked copy.
    assert log.gyro.strides == (12 * 8, 8) and log.accel.strides == (12 * 8, 8)
    np.testing.assert_array_equal(log.gyro[:, 1], t["gyro_y"])
    assert not log.gyro.flags.writeable
