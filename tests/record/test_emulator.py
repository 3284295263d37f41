"""The emulator answers like a VN-100: checked replies, $VNERR codes for bad input."""

from __future__ import annotations

import pytest
from imunoise.recording.protocol import crc16, error_name, parse_reply, sentence
from imunoise.recording.session import Session, open_port


def test_checksums_match_the_protocol_vectors():
    assert crc16(b"123456789") == 0x31C3
    assert sentence("VNRRG,30,0,0,0,0,1,0,1") == b"$VNRRG,30,0,0,0,0,1,0,1*6C\r\n"
    assert sentence("VNERR,03") == b"$VNERR,03*72\r\n"
    assert parse_reply(b"$VNYPR,+010.071,+000.278,-002.026*60\r\n").fields[0] == "+010.071"
    assert parse_reply(b"$VNYPR,+010.071,+000.278,-002.026*61\r\n") is None
    assert parse_reply(sentence("VNRRG,15", crc=True)).header == "VNRRG"


@pytest.mark.parametrize("raw, code", [
    (b"$VNRRG,01*00\r\n", 0x03),                 # bad checksum
    (b"$VNFOO*XX\r\n", 0x04),                    # unknown command
    (b"$VNRRG,99*XX\r\n", 0x08),                 # no such register
    (b"$VNWRG,01,VN-200*XX\r\n", 0x09),          # identity is read-only
    (b"$VNWRG,07,33*XX\r\n", 0x07),              # not a rate register 7 takes
    (b"$VNWRG,30,0,0,0*XX\r\n", 0x05),           # register 30 has 7 fields
])
def test_bad_input_gets_its_vnerr(emulator, raw, code):
    emu = emulator(seed=9)
    port = open_port(emu.path, 115200)
    try:
        session = Session(port)
        session.command("VNASY,0")
        port.write(raw)
        received = bytearray()
        errors: list[int] = []
        for _ in range(500):  # until the reply is in (give up after 10 s)
            received += port.read(4096)
            replies = [parse_reply(line) for line in bytes(received).split(b"\n")[:-1]]
            errors = [r.error for r in replies if r is not None and r.error is not None]
            if errors:
                break
        assert errors == [code], (error_name(code), bytes(received[-300:]))
    finally:
        port.close()
