"""The format registry: detection by confidence, dispatch, one entry per format."""

from __future__ import annotations

import imunoise
import pytest
from imunoise.readers import registry
from imunoise.readers.probe import Confidence, Probe
from imunoise.readers.read import FORMATS, detect_format

YMR = b"$VNYMR,+100.949,-007.330,+000.715,-00.0049,-00.2449,+00.5397,-01.258,-00.100,-09.701,-00.000018,+00.001122,-00.000551*69\r\n"  # noqa: E501


def test_every_format_has_one_entry():
    assert FORMATS == ("auto", "vn-ascii", "vn-binary", "csv", "rosbag", "columnar")
    assert registry.names() == FORMATS[1:]
    # what scale.convert needs to know: which formats the VN stream parser reads
    assert {f.name for f in registry.FORMATS if f.streamable} == {"vn-ascii", "vn-binary"}
    assert registry.get("csv").name == "csv"
    with pytest.raises(ValueError, match=r"format must be one of \('vn-ascii'.*got 'nmea'"):
        registry.get("nmea")
    with pytest.raises(ValueError, match=r"format must be one of \('auto'.*got 'nmea'"):
        imunoise.read(b"", format="nmea")


def test_surest_format_wins(tmp_path):
    # a magic number beats an extension, an extension beats the content
    fake_bag = tmp_path / "x.csv"
    fake_bag.write_bytes(b"#ROSBAG V2.0\n" + YMR)
    assert detect_format(fake_bag) == "rosbag"
    named_bag = tmp_path / "x.bag"
    named_bag.write_bytes(YMR)
    assert detect_format(named_bag) == "rosbag"
    named_csv = tmp_path / "x.tsv"
    named_csv.write_bytes(YMR)
    assert detect_format(named_csv) == "csv"
    # VN records beat the guess that text with commas is CSV
    assert detect_format(YMR * 3) == "vn-ascii"
    assert detect_format(b"\xfa\x01" * 4 + YMR) == "vn-binary"
    assert detect_format(b"a b\n1 2\n") == "csv"


def test_directories(tmp_path):
    not_a_bag = tmp_path / "logs.csv"
    not_a_bag.mkdir()
    with pytest.raises(ValueError, match="is a directory but not a ROS 2 bag"):
        detect_format(not_a_bag)
    (not_a_bag / "bag_0.mcap").write_bytes(b"\x89MCAP0\r\n")
    assert detect_format(not_a_bag) == "rosbag"


def test_probe_reads_the_file_once_and_only_on_demand(tmp_path):
    path = tmp_path / "x.bag"
    probe = Probe(path)
    assert probe.suffix == ".bag" and not probe.is_dir  # no read needed
    path.write_bytes(b"ab")
    assert probe.head == b"ab"
    path.write_bytes(b"cd")
    assert probe.head == b"ab"
    assert Probe(memoryview(b"xyz")).head == b"xyz" and Probe(b"").suffix == ""


def test_a_new_format_is_one_entry(monkeypatch):
    calls = []

    def sniff(probe):
        return Confidence.SIGNATURE if probe.head.startswith(b"TOY") else Confidence.NO

    def read_toy(source, *, strict, fs, progress):
        calls.append(source)
        return "toy log"

    toy = registry.Format("toy", sniff, read_toy)
    monkeypatch.setattr(registry, "FORMATS", (*registry.FORMATS, toy))
    assert detect_format(b"TOY,1,2\n") == "toy"
    assert imunoise.read(b"TOY,1,2\n") == "toy log"
    assert imunoise.read(b"1,2\n", format="toy") == "toy log"
    assert calls == [b"TOY,1,2\n", b"1,2\n"]


@pytest.mark.parametrize("fmt", ["auto", "vn-ascii", "vn-binary", "csv", "rosbag"])
@pytest.mark.parametrize("name", ["missing.txt", "missing.csv", "missing.bag"])
def test_missing_file_is_file_not_found(tmp_path, fmt, name):
    path = tmp_path / name
    with pytest.raises(FileNotFoundError) as info:
        imunoise.read(path, format=fmt)
    assert info.value.filename == str(path)
    if fmt == "auto":
        with pytest.raises(FileNotFoundError):
            detect_format(path)
