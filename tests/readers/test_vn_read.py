"""imunoise.read: format detection and dispatch to the CSV and ROS bag readers."""

from dataclasses import replace

import imunoise
import pytest
from helpers.data import DATA
from imunoise.readers import registry
from imunoise.readers.read import detect_format
from imunoise.readers.vn import parse_vn_sentences

YMR = b"$VNYMR,+100.949,-007.330,+000.715,-00.0049,-00.2449,+00.5397,-01.258,-00.100,-09.701,-00.000018,+00.001122,-00.000551*69"  # noqa: E501


def test_detect(tmp_path):
    assert detect_format(DATA / "rugged_0513test.txt") == "vn-ascii"
    assert detect_format(DATA / "waves_F00294.bin") == "vn-binary"
    assert detect_format(b"#ROSBAG V2.0\n...") == "rosbag"
    assert detect_format(b"\x89MCAP0\r\n") == "rosbag"
    assert detect_format(b"t,gx,gy,gz\n0,1,2,3\n") == "csv"
    p = tmp_path / "x.csv"
    p.write_bytes(b"raw\n" + YMR + b"\n")
    assert detect_format(p) == "csv"
    (tmp_path / "bag").mkdir()
    (tmp_path / "bag" / "metadata.yaml").write_text("x")
    assert detect_format(tmp_path / "bag") == "rosbag"
    with pytest.raises(ValueError, match="could not recognise"):
        detect_format(b"\x00\x01\x02")


@pytest.mark.parametrize("fmt", ["csv", "rosbag"])
def test_dispatch(monkeypatch, fmt):
    calls = []

    def reader(source, *, strict, fs, progress):
        calls.append((source, strict, fs, progress))
        return "log"

    entries = [replace(f, read=reader) if f.name == fmt else f for f in registry.FORMATS]
    monkeypatch.setattr(registry, "FORMATS", tuple(entries))
    assert imunoise.read(b"a,b\n1,2\n", format=fmt, strict=True, fs=5.0) == "log"
    assert calls == [(b"a,b\n1,2\n", True, 5.0, None)]
    with pytest.warns(DeprecationWarning, match="format= by keyword"):
        assert imunoise.read(b"a,b\n1,2\n", fmt) == "log"
    assert calls[-1] == (b"a,b\n1,2\n", False, None, None)


def test_parse_vn_sentences_embedded():
    text = b'1.0,"' + YMR + b'"\n2.0,"' + YMR + b'"\n'
    log = parse_vn_sentences(text, fs=40.0, source="x.csv")
    assert log.messages == {"VNYMR": 2} and log.source == "x.csv" and log.fs == 40.0
    assert log.issues.total == 0 and log.issues.counts["bytes_skipped"] == len(text) - 2 * (
        len(YMR)
    )
    with pytest.raises(TypeError, match="data must be bytes"):
        parse_vn_sentences("text")
