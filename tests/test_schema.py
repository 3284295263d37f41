"""One source of truth: shared names and constants come from one place, and the
API helpers that keep old call forms working warn and forward exactly."""

import math

import imunoise
import numpy as np
import pytest
from imunoise import noise, units
from imunoise._core import fit as core_fit
from imunoise._support import schema as _schema
from imunoise.readers import log as readers_log


def test_fit_constants_are_the_rust_ones():
    assert noise.TERMS == ("Q", "N", "B", "K", "R") == tuple(core_fit.IEEE_TERM_NAMES)
    assert noise.GM_MAX == core_fit.MAX_GAUSS_MARKOV == 3
    assert noise.TONES_MAX == core_fit.MAX_TONES == 2
    # one Python class per Rust term kind, with the same parameters
    kinds = {name: (params, coords) for name, params, coords in core_fit.TERM_KINDS}
    assert list(kinds) == list(noise._typed.KINDS)
    assert [k for k in kinds if len(kinds[k][0]) == 1] == [
        cls.kind for cls in noise._typed.IEEE.values()]
    for name, cls in noise._typed.KINDS.items():
        assert len(cls.from_core(*_unit_core(kinds[name])).core()[1]) == len(kinds[name][0])
    assert noise.FLICKER == pytest.approx(math.sqrt(2 * math.log(2) / math.pi), rel=1e-15)


def _unit_core(names):
    params, coords = names
    values = [0.5 if p == "skew" else 1.0 for p in params]
    return values, np.eye(len(coords))


def test_channel_table_and_gravity_have_one_home():
    assert readers_log.CHANNELS is _schema.CHANNELS
    assert units.G == _schema.G == 9.80665
    assert _schema.column_names("quaternion") == [
        "quaternion_x", "quaternion_y", "quaternion_z", "quaternion_w"]
    assert _schema.column_names("temperature") == ["temperature"]


def test_axis_names():
    assert _schema.axis_names(3) == ["X", "Y", "Z"]
    assert _schema.axis_names(1) == ["value"]
    assert _schema.axis_names(6) == [f"ch{i}" for i in range(6)]
    with pytest.raises(ValueError, match="axes must name 3 channels"):
        _schema.axis_names(3, ["a", "b"])
    assert _schema.sensor_label("gyro", 2, 3) == "gyro Z"


def test_fit_options_by_position_still_work_with_a_warning():
    r = imunoise.adev(np.random.default_rng(1).normal(size=20_000), 100.0)
    with pytest.warns(DeprecationWarning, match="pass method= by keyword"):
        old = imunoise.fit(r, "slopes")
    new = imunoise.fit(r, method="slopes")
    assert np.array_equal(old.N, new.N)


def test_parse_error_carries_its_location():
    from imunoise.errors import ParseError

    e = ParseError("checksum 0x12 != 0x34", kind="bad_checksum", line=7, offset=120,
                   source="log.txt")
    assert isinstance(e, ValueError)
    assert (e.kind, e.line, e.offset, e.source) == ("bad_checksum", 7, 120, "log.txt")
    assert str(e) == "log.txt, line 7, byte offset 120: bad_checksum: checksum 0x12 != 0x34"
    import pickle

    again = pickle.loads(pickle.dumps(e))
    assert (again.kind, again.line, str(again)) == (e.kind, e.line, str(e))
