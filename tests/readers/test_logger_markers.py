"""VN-100 binary logs with a logger's text markers between the packets.

The LoggerWavesInIce logger writes its own lines (``S,Booting from beginning!``,
``M,<millis>``, ``B,``) between the VN-100's binary packets; such a log once
started with two comma-separated lines and was taken for a CSV ("no IMU columns
recognised in ['S', 'Booting from beginning!']"). Built here from the packets of
``waves_F00294.bin`` (in the repository) in the shape of the logger's
``F00379`` (which begins with the boot marker), so no file outside the
repository is needed.
"""

import imunoise
from helpers.data import DATA
from imunoise.readers.probe import Confidence, Probe
from imunoise.readers.read import detect_format
from imunoise.readers.registry import CHECKED_PACKETS, _sniff_vn_binary

HEADER = b"\xfa\x14\x3e\x00\x3a\x00"
PACKET = 124  # bytes of one packet of this output configuration


def _packets(n: int) -> list[bytes]:
    data = (DATA / "waves_F00294.bin").read_bytes()
    found, at = [], data.find(HEADER)
    while at >= 0 and len(found) < n:
        found.append(data[at:at + PACKET])
        at = data.find(HEADER, at + PACKET)
    assert len(found) == n
    return found


def _log(n: int) -> tuple[bytes, int]:
    """A log of ``n`` packets, the boot markers first; returns it and its marker bytes."""
    boot = b"S,Booting from beginning!\n\r\nR,0\nC,0.00\n"
    parts, markers = [boot], len(boot)
    for i, packet in enumerate(_packets(n)):
        mark = f"M,{6865 + 100 * i}\n\r\nB,\n\r\n".encode()
        parts += [mark, packet]
        markers += len(mark)
    return b"".join(parts), markers


def test_boot_marker_first_is_vn_binary(tmp_path):
    data, markers = _log(40)
    path = tmp_path / "F00379"
    path.write_bytes(data)
    assert detect_format(path) == "vn-binary"
    assert detect_format(data) == "vn-binary"
    log = imunoise.read(path, fs=10.0)
    assert log.format == "vn-binary" and len(log) == 40
    assert log.messages == {"binary_143e003a00": 40}
    # every marker byte is reported as skipped, nothing else
    assert log.issues.counts["bytes_skipped"] == markers
    assert log.issues.total == 0


def test_a_csv_name_does_not_hide_checked_packets(tmp_path):
    data, _ = _log(5)
    path = tmp_path / "log.csv"
    path.write_bytes(data)
    assert _sniff_vn_binary(Probe(path)) == Confidence.CHECKED
    assert detect_format(path) == "vn-binary"


def test_one_packet_or_bad_crcs_are_not_enough():
    data, _ = _log(CHECKED_PACKETS)
    one = data[:data.rfind(HEADER)]  # the last packet cut off
    assert _sniff_vn_binary(Probe(one)) == Confidence.CONTENT
    broken = data.replace(HEADER, HEADER[:-1] + b"\x01")  # packets with wrong headers
    assert _sniff_vn_binary(Probe(broken)) <= Confidence.CONTENT
    assert detect_format(b"t,gx,gy,gz\n0,1,2,3\n") == "csv"
