"""Damaged bags (bit flips, truncation, zeroed blocks) of the three formats: nothing but
ParseError, or a ValueError/OSError naming the file, reaches the caller; the CLI gives
one line and exit 2. ``benches/faults.py bags`` runs the same at >= 10,000 per bag."""

import random

import pytest
from helpers.bags import KINDS, mutate, outcome, small_bags
from imunoise.cli import main

PER_BAG = 100


@pytest.fixture(scope="module")
def bags(tmp_path_factory):
    return small_bags(tmp_path_factory.mktemp("bags"))


@pytest.mark.parametrize("fmt", ["ros1", "db3", "mcap"])
def test_damaged_bags_raise_only_parse_errors(bags, fmt, tmp_path):
    src = bags[fmt]
    data = src.read_bytes()
    rng = random.Random(f"{fmt}-mutations")
    damaged = tmp_path / f"damaged{src.suffix}"
    seen, leaks = {}, []
    for i in range(PER_BAG):
        kind, body = mutate(data, rng, KINDS[i % len(KINDS)])
        damaged.write_bytes(body)
        result = outcome(damaged)
        seen[result] = seen.get(result, 0) + 1
        if result.startswith("LEAK"):
            leaks.append((kind, result))
    assert not leaks, leaks[:5]
    assert seen.get("ParseError", 0) + sum(v for k, v in seen.items() if k.startswith("named"))


def test_an_mcap_of_only_its_magic_is_a_parse_error(tmp_path, capsys):
    magic = tmp_path / "magic.mcap"
    magic.write_bytes(b"\x89MCAP0\r\n")
    assert outcome(magic) == "ParseError"  # was TypeError: ord() expected a character
    assert main(["stats", str(magic)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "magic.mcap" in err[0] and "damaged bag" in err[0]


def test_the_cli_gives_one_line_for_a_library_error(bags, tmp_path, capsys):
    """A ROS 1 bag whose first record header is zeroed made rosbags raise its ReaderError."""
    body = bytearray(bags["ros1"].read_bytes())
    body[13:13 + 256] = bytes(256)
    bad = tmp_path / "zeroed.bag"
    bad.write_bytes(bytes(body))
    assert main(["stats", str(bad)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "zeroed.bag" in err[0]


def test_a_size_field_beyond_memory_is_a_parse_error(bags, monkeypatch):
    """rosbags reads a record of the size the file claims: a damaged size made it raise
    MemoryError (when the machine could not give the memory), which leaked."""
    import imunoise
    from imunoise.errors import ParseError
    from rosbags.highlevel import AnyReader

    def claims_too_much(self):
        raise MemoryError

    monkeypatch.setattr(AnyReader, "open", claims_too_much)
    with pytest.raises(ParseError, match=r"11sec_motion_0\.mcap.*size field asks for more"):
        imunoise.read(bags["mcap"])
