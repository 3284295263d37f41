"""Every reader error names the file: damage behind metadata that still fits
(the metadata's fingerprint rewritten to the damaged data, so the reader itself
meets the damage) and damage to the files that carry their metadata inside."""

import json
import random
import shutil

import imunoise
import numpy as np
import pytest
from helpers.data import DATA
from imunoise import scale
from imunoise._support.atomic import fingerprint
from imunoise.cli import main
from imunoise.errors import ParseError


@pytest.fixture(scope="module")
def outputs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("named")
    raw = (DATA / "rugged_0513test.txt").read_bytes().splitlines(keepends=True)
    src = tmp / "src.txt"
    src.write_bytes(b"".join(raw[1:301]))
    made = {}
    for suffix in (".npy", ".npz", ".parquet", ""):
        out = tmp / f"o{suffix}"
        assert main(["convert", str(src), "-o", str(out), "--fs", "40", "--no-progress"]) == 0
        made[suffix or "dir"] = out
    return made


def _retie(meta_file, name, data_file):
    meta = json.loads(meta_file.read_text())
    if name is None:
        meta["data"] = fingerprint(data_file)
    else:
        meta["data"][name] = fingerprint(data_file)
    meta_file.write_text(json.dumps(meta))


@pytest.mark.parametrize(("channel", "array", "match"), [
    ("gyro", np.zeros(300), r"gyro must have shape \(n, 3\)"),
    ("accel", np.zeros((300, 2)), r"accel must have shape \(n, 3\)"),
    ("mag", np.zeros((10, 3)), "the metadata says 300 samples"),
    ("ypr", None, "not a readable .npy"),  # cut: 'mmap length is greater than file size'
])
def test_a_directory_channel_that_does_not_fit(outputs, tmp_path, channel, array, match):
    out = tmp_path / "o"
    shutil.copytree(outputs["dir"], out)
    path = out / f"{channel}.npy"
    if array is None:
        path.write_bytes(path.read_bytes()[:-100])
    else:
        np.save(path, array)
    _retie(out / "meta.json", f"{channel}.npy", path)
    for reader in (imunoise.read, scale.load):
        with pytest.raises(ParseError, match=match) as info:
            reader(out)
        assert str(out) in str(info.value)


@pytest.mark.parametrize("at", [8, 10, 30, 60])
def test_a_damaged_npy_header(outputs, tmp_path, at):
    out = tmp_path / "o.npy"
    data = bytearray(outputs[".npy"].read_bytes())
    data[at:at + 4] = b"((\n("  # numpy's header parser raised a tokenize error here
    out.write_bytes(bytes(data))
    shutil.copy(outputs[".npy"].with_name("o.npy.meta.json"), tmp_path)
    _retie(tmp_path / "o.npy.meta.json", None, out)
    with pytest.raises(ParseError) as info:
        imunoise.read(out)
    assert str(out) in str(info.value)


@pytest.mark.parametrize("kind", [".npz", ".parquet"])
def test_damaged_files_with_their_metadata_inside(outputs, tmp_path, kind):
    if kind == ".parquet":
        pytest.importorskip("pyarrow")
    rng = random.Random(7)
    data = outputs[kind].read_bytes()
    for i in range(60):
        damaged = bytearray(data)
        if i % 3 == 0:
            damaged = damaged[:rng.randrange(len(damaged))]
        else:
            for _ in range(1 + i % 5):
                damaged[rng.randrange(len(damaged))] = rng.randrange(256)
        path = tmp_path / f"m{i}{kind}"
        path.write_bytes(bytes(damaged))
        try:
            imunoise.read(path)
        except ValueError as exc:
            assert str(path) in str(exc), exc


def test_a_parse_error_without_a_file_gets_the_name(outputs, tmp_path):
    from imunoise.readers.read import naming

    with pytest.raises(ParseError) as info, naming(tmp_path / "x.bin"):
        raise ParseError("bad", kind="malformed_field")
    assert info.value.source == str(tmp_path / "x.bin")
    with pytest.raises(ValueError, match=r"^.*x\.bin: mmap length"), naming(tmp_path / "x.bin"):
        raise ValueError("mmap length is greater than file size")
    with pytest.raises(ParseError, match=r"x\.bin.*OverflowError"), naming(tmp_path / "x.bin"):
        raise OverflowError("cannot convert float infinity to integer")
