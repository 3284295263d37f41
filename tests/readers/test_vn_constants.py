"""The names and numbers the VN parser owns reach Python from Rust, unchanged."""

from __future__ import annotations

from imunoise._core import vn as _core_vn
from imunoise.readers import ISSUE_KINDS, _sentences


def test_issue_kinds_are_the_parsers_then_the_grids():
    # The public tuple keeps its content and order (counts are reported in it).
    assert ISSUE_KINDS == (
        "bad_checksum",
        "malformed_field",
        "unknown_message",
        "truncated_record",
        "bytes_skipped",
        "device_error",
        "duplicate_time",
        "time_reversed",
        "time_outlier",
        "time_reset",
    )
    assert ISSUE_KINDS[: len(_core_vn.ISSUE_KINDS)] == _core_vn.ISSUE_KINDS


def test_every_reader_keeps_the_parsers_number_of_first_locations():
    assert _core_vn.FIRST_KEEP == 5
    assert _sentences.MAX_FIRST == _core_vn.FIRST_KEEP


def test_binary_field_table_lists_the_writable_groups():
    fields = _core_vn.vn_binary_fields()
    assert [g for g, _ in fields.values()] == [0, 1, 2, 4]
    assert all("reserved" not in names for _, names in fields.values())
