"""The kind registry of imunoise.allan against the Rust statistic table, and the
typed boundary to the core (imunoise._core.allan)."""

import imunoise
import numpy as np
import pytest
from imunoise import allan
from imunoise._core import allan as core_allan

Y = np.random.default_rng(3).normal(size=400)


def test_the_registry_uses_exactly_the_core_statistics():
    used = set().union(*(kind.statistics for kind in allan._REGISTRY.values()))
    assert used == set(core_allan.STATISTICS)
    assert len(core_allan.STATISTICS) == len(set(core_allan.STATISTICS))


def test_gap_skipping_is_the_difference_family():
    assert core_allan.GAP_SKIPPING == ("adev", "oadev", "mdev", "hdev", "ohdev")
    assert allan._SKIPS_GAPS == set(core_allan.GAP_SKIPPING)


def test_every_kind_is_a_public_function_whose_result_names_it():
    assert allan.KINDS == tuple(allan._REGISTRY)
    for name in allan.KINDS:
        assert name in allan.__all__ and name in imunoise.__all__
        assert getattr(imunoise, name) is getattr(allan, name)
        assert getattr(allan, name)(Y, 1.0).kind == name


def test_the_cli_offers_every_kind():
    from imunoise import cli

    assert tuple(cli.KINDS) == allan.KINDS


def test_options_are_keyword_only():
    with pytest.raises(TypeError):
        imunoise.adev(Y, 1.0, "decade")  # type: ignore[misc]
    assert np.array_equal(imunoise.adev(Y, 1.0, taus="decade").m, [1, 2, 4, 10, 20, 40, 100])


def test_theobr_minimum_is_the_core_constant():
    shortest = core_allan.THEOBR_MIN_SAMPLES
    assert shortest == 89
    assert len(imunoise.theobr(Y[:shortest], 1.0)) > 0
    with pytest.raises(ValueError, match=f"at least {shortest} samples"):
        imunoise.theobr(Y[: shortest - 1], 1.0)


def test_analysis_is_a_frozen_object_with_named_arrays():
    x = np.stack([Y, 2 * Y], axis=1)
    x[7, 1] = np.nan
    ms = np.array([1, 2, 4], dtype=np.uint64)
    a = core_allan.analyse(x, "oadev", ms)
    assert isinstance(a, core_allan.Analysis)
    for name, dtype in [("var", np.float64), ("terms", np.uint64), ("alpha", np.int32),
                        ("alpha_identified", np.bool_), ("edf", np.float64)]:
        assert getattr(a, name).shape == (3, 2) and getattr(a, name).dtype == dtype
    assert a.missing.tolist() == [0, 1]
    with pytest.raises(AttributeError):
        a.var = a.edf  # type: ignore[misc]
    with pytest.raises(ValueError, match='statistic must be one of adev, oadev.*got "avar"'):
        core_allan.analyse(x, "avar", ms)


def test_results_carry_the_record_length():
    assert imunoise.adev(Y, 1.0).n_samples == 400
    gapped = Y.copy()
    gapped[100:110] = np.nan
    assert imunoise.adev(gapped, 1.0).n_samples == 400
    with pytest.warns(UserWarning):
        assert imunoise.adev(gapped, 1.0, gaps="splice").n_samples == 390
    with pytest.warns(UserWarning):
        assert imunoise.totdev(gapped, 1.0, gaps="longest").n_samples == 290
