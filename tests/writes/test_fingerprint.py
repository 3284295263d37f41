"""The data's fingerprint in metadata: bytes, modification time and a BLAKE3 digest
hashed by the core (by convert while it writes the rows, the header joining at the
end); metadata written by earlier versions carries a SHA-256 instead and still
verifies. Either digest refuses changed data; a malformed fingerprint
is an error naming the field."""

import hashlib
import json
import os
from pathlib import Path

import imunoise
import pytest
from helpers.data import DATA
from imunoise._support import atomic as _atomic
from imunoise.cli import main
from imunoise.errors import ParseError
from imunoise.readers import metafile

#: BLAKE3's official test vectors (test_vectors/test_vectors.json of the reference
#: repository, the first 32 bytes of "hash"): input length -> digest, the input
#: being bytes 0, 1, ..., 250, 0, 1, ... (i mod 251).
VECTORS = {
    0: "af1349b9f5f9a1a6a0404dea36dcc9499bcb25c9adc112b7cc9a93cae41f3262",
    1: "2d3adedff11b61f14c886e35afa036736dcd87a74d27b5c1510225d0f592e213",
    1025: "d00278ae47eb27b34faecf67b4fe263f82d5412916c1ffd97c8cb7fb814b8444",
    102400: "bc3e3d41a1146b069abffad3c0d44860cf664390afce4d9661f7902e7943e085",
}


def _pattern(n: int) -> bytes:
    return (bytes(range(251)) * (n // 251 + 1))[:n]


@pytest.mark.parametrize("n", sorted(VECTORS))
def test_the_digest_is_the_official_test_vectors(n, tmp_path):
    path = tmp_path / "d"
    path.write_bytes(_pattern(n))
    mark = _atomic.fingerprint(path)
    st = os.stat(path)
    assert mark == {"bytes": n, "mtime_ns": st.st_mtime_ns, "blake3": VECTORS[n]}


# 1 MiB + 1 (past the sizes of the official vectors) and more than two of the
# core's 16 MiB blocks, in which it maps and hashes a file
@pytest.mark.parametrize("n", [(1 << 20) + 1, (33 << 20) + 12345])
def test_the_digest_of_large_files_is_the_oracles(n, tmp_path):
    blake3 = pytest.importorskip("blake3", reason="the oracle is a test extra")
    data = os.urandom(n)
    path = tmp_path / "d"
    path.write_bytes(data)
    assert _atomic.fingerprint(path)["blake3"] == blake3.blake3(data).hexdigest()


def _converted(tmp_path: Path, digest: str) -> Path:
    """A small .npy convert wrote; with ``digest="sha256"`` its metadata rewritten
    as earlier versions wrote it (the same fingerprint with a SHA-256)."""
    src = tmp_path / "src.txt"
    raw = (DATA / "rugged_0513test.txt").read_bytes().splitlines(keepends=True)
    src.write_bytes(b"".join(raw[1:201]))
    out = tmp_path / "log.npy"
    assert main(["convert", str(src), "-o", str(out), "--fs", "40", "--no-progress"]) == 0
    side = metafile.meta_path(out)
    meta = json.loads(side.read_text())
    assert set(meta["data"]) == {"bytes", "mtime_ns", "blake3"}
    if digest == "sha256":
        del meta["data"]["blake3"]
        meta["data"]["sha256"] = hashlib.sha256(out.read_bytes()).hexdigest()
        side.write_text(json.dumps(meta))
    return out


@pytest.mark.parametrize("layout", [".npy", "dir"])
def test_the_digest_convert_hashes_while_writing_is_the_files(layout, tmp_path):
    src = tmp_path / "src.txt"
    src.write_bytes((DATA / "rugged_0513test.txt").read_bytes())
    out = tmp_path / ("log.npy" if layout == ".npy" else "log")
    assert main(["convert", str(src), "-o", str(out), "--fs", "40", "--no-progress"]) == 0
    if layout == ".npy":
        marks = {out: json.loads(metafile.meta_path(out).read_text())["data"]}
    else:
        ties = json.loads((out / "meta.json").read_text())["data"]
        marks = {out / name: mark for name, mark in ties.items()}
    assert len(marks) >= (1 if layout == ".npy" else 4)
    for path, mark in marks.items():
        assert path.stat().st_size > 2048  # spans past the header's first chunk
        assert mark == _atomic.fingerprint(path)


@pytest.mark.parametrize(("digest", "name"), [("blake3", "BLAKE3"), ("sha256", "SHA-256")])
def test_both_digests_verify_a_copy_and_refuse_changed_data(digest, name, tmp_path):
    out = _converted(tmp_path, digest)
    assert len(imunoise.read(out)) == 200  # the same modification time: the fast path
    copy = tmp_path / "copy"
    copy.mkdir()
    for source in (out, metafile.meta_path(out)):  # a copy's new mtime: the digest decides
        (copy / source.name).write_bytes(source.read_bytes())
    assert len(imunoise.read(copy / out.name)) == 200
    data = bytearray((copy / out.name).read_bytes())
    data[-1] ^= 1  # one bit of the last sample: same size, other content
    (copy / out.name).write_bytes(bytes(data))
    with pytest.raises(ParseError, match=rf"log\.npy\.meta\.json describes \d+ bytes with "
                       rf"{name} [0-9a-f]{{12}}\.\.\. but .* is other data"):
        imunoise.read(copy / out.name)


_GOOD = {"bytes": 1, "mtime_ns": 2}
_HEX = "0123456789abcdef" * 4


@pytest.mark.parametrize(("tie", "field", "says"), [
    ({**_GOOD}, "'data'",
     "must carry exactly one digest, 'blake3' or 'sha256'; got neither"),
    ({**_GOOD, "blake3": _HEX, "sha256": _HEX}, "'data'",
     "must carry exactly one digest, .*; got 'blake3' and 'sha256'"),
    ({**_GOOD, "blake3": _HEX[:63]}, "'data.blake3'", "must be 64 hex digits; got '0123"),
    ({**_GOOD, "blake3": _HEX.upper()}, "'data.blake3'", "must be 64 hex digits"),
    ({**_GOOD, "sha256": 7}, "'data.sha256'", "must be 64 hex digits; got 7"),
    ({"bytes": -1, "blake3": _HEX}, "'data.bytes'", r"must be a count in \[0, "),
    ([_HEX], "'data'", "must be an object"),
])
def test_a_malformed_fingerprint_names_its_field(tie, field, says):
    with pytest.raises(ParseError, match=rf"metadata field {field} {says}"):
        metafile.tie_fields(tie, "m.json")


def test_well_formed_fingerprints_of_either_digest_are_taken():
    for key in metafile.DIGESTS:
        tie = {**_GOOD, key: _HEX}
        assert metafile.tie_fields(tie, "m.json") is tie
