"""Damaged streams: every good record recovered, every bad one counted, every byte
accounted for; strict mode raises ValueError only."""

import imunoise
import numpy as np
import pytest
from helpers.data import DATA
from helpers.vn_oracle import good_sentences
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from imunoise.readers.vn import read_vn_tables

RUGGED = (DATA / "rugged_0513test.txt").read_bytes()
# The complete lines of the real log (drop the truncated first and last lines).
LINES = RUGGED.split(b"\n")[1:-1]
WAVES = (DATA / "waves_F00294.bin").read_bytes()
HEADER = bytes.fromhex("fa143e003a00")


def accounted(t) -> bool:
    return t.bytes_parsed + t.bytes_in_bad_records + t.bytes_skipped == t.bytes_total


def test_clean_lines():
    t = read_vn_tables(b"\n".join(LINES) + b"\n", strict=True)
    assert t.messages == {"VNYMR": 3902} and t.issues.total == 0


def test_bad_checksums_counted_and_others_kept():
    rng = np.random.default_rng(3)
    lines = list(LINES)
    bad = sorted(rng.choice(len(lines), 57, replace=False))
    for i in bad:
        body, check = lines[i].rsplit(b"*", 1)
        lines[i] = body + b"*" + b"%02X" % ((int(check, 16) + 1) % 256)
    data = b"\r\n".join(lines) + b"\r\n"
    t = read_vn_tables(data)
    assert t.issues.counts["bad_checksum"] == 57
    assert t.messages["VNYMR"] == 3902 - 57
    assert t.issues.first["bad_checksum"] == tuple(int(i) + 1 for i in bad[:5])
    expected = np.array(good_sentences(data))
    np.testing.assert_array_equal(t.tables["VNYMR"]["gyro_z"], expected[:, 11])
    with pytest.raises(ValueError, match=f"line {bad[0] + 1} .*bad_checksum"):
        read_vn_tables(data, strict=True)


def test_truncated_lines_and_inserted_noise():
    rng = np.random.default_rng(4)
    lines = list(LINES)
    cut = set(rng.choice(len(lines), 40, replace=False).tolist())
    noisy = set(rng.choice(len(lines), 60, replace=False).tolist()) - cut
    out, inserted = [], 0
    for i, line in enumerate(lines):
        if i in cut:
            line = line[: int(rng.integers(1, len(line) - 3))]
        out.append(line + b"\n")
        if i in noisy:
            # Noise between records: random bytes without '$', 0xFA.
            junk = bytes(b for b in rng.integers(0, 256, 30).astype(np.uint8) if b not in b"$\xfa")
            out.append(junk)
            inserted += len(junk)
    data = b"".join(out)
    t = read_vn_tables(data)
    assert t.messages["VNYMR"] == 3902 - len(cut)
    assert t.issues.counts["truncated_record"] == len(cut)
    assert t.issues.counts["bytes_skipped"] == inserted
    assert accounted(t)


def test_binary_damage():
    starts = [i for i in range(len(WAVES)) if WAVES.startswith(HEADER, i)]
    assert len(starts) == 99
    data = bytearray(WAVES)
    hit = starts[10], starts[50], starts[98]
    for s in hit:
        data[s + 40] ^= 0x10
    t = read_vn_tables(bytes(data))
    assert t.binary_records == 96 and t.issues.counts["bad_checksum"] == 3
    assert t.issues.first["bad_checksum"] == hit
    # A cut last packet is reported, not lost silently.
    t = read_vn_tables(WAVES[: starts[98] + 60])
    assert t.binary_records == 98 and t.issues.counts["truncated_record"] == 1
    with pytest.raises(ValueError, match=f"byte offset {starts[98]}"):
        read_vn_tables(WAVES[: starts[98] + 60], strict=True)


def test_file_and_bytes_agree_with_progress(tmp_path):
    data = (b"\n".join(LINES) + b"\n") * 6 + WAVES
    path = tmp_path / "mixed.bin"
    path.write_bytes(data)
    calls = []
    from_file = read_vn_tables(path, progress=lambda done, total: calls.append((done, total)))
    from_bytes = read_vn_tables(data)
    assert calls and calls[-1] == (len(data), len(data))
    assert from_file.messages == from_bytes.messages
    for name, cols in from_bytes.tables.items():
        for col, arr in cols.items():
            np.testing.assert_array_equal(from_file.tables[name][col], arr)

    def boom(done, total):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        read_vn_tables(path, progress=boom)


def test_read_errors():
    with pytest.raises(ValueError, match="format must be one of"):
        imunoise.read(b"", format="nmea")
    with pytest.raises(TypeError, match="source must be"):
        imunoise.read(3.5)
    with pytest.raises(FileNotFoundError):
        imunoise.read(DATA / "does-not-exist.txt", format="vn-ascii")


SEED = b"".join(LINES[:3]) + WAVES[64:64 + 124 * 2] + b"\r\n".join(LINES[3:5])


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.binary(max_size=2000))
def test_random_bytes(data):
    t = read_vn_tables(data)
    assert t.bytes_total == len(data) and accounted(t)
    try:
        read_vn_tables(data, strict=True)
    except ValueError:
        pass


@settings(max_examples=150, deadline=None)
@given(
    st.lists(
        st.tuples(st.integers(0, len(SEED)), st.integers(0, 255), st.sampled_from("ids")),
        max_size=12,
    )
)
def test_mutated_streams(edits):
    data = bytearray(SEED)
    for pos, byte, op in edits:
        pos = min(pos, len(data))
        if op == "i":
            data.insert(pos, byte)
        elif pos < len(data):
            if op == "d":
                del data[pos]
            else:
                data[pos] = byte
    data = bytes(data)
    t = read_vn_tables(data)
    assert t.bytes_total == len(data) and accounted(t)
    # Every sentence the oracle accepts is decoded.
    assert t.messages.get("VNYMR", 0) >= len(good_sentences(data))
    try:
        read_vn_tables(data, strict=True)
    except ValueError:
        pass
