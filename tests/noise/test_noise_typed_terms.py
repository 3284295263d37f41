"""``model.terms``: each channel's fitted terms as typed objects, the same numbers
as the parallel arrays of ``model.components`` and the same curve as the model."""

from __future__ import annotations

import math
from dataclasses import fields
from operator import attrgetter

import imunoise
import numpy as np
import pytest
from imunoise import noise
from imunoise._core import fit as core_fit

FS = 100.0


@pytest.fixture(scope="module")
def model():
    # white + flicker + a tone on channel 0, white + a slow Gauss-Markov bias on 1
    n = 360_000
    a = imunoise.simulate(n, FS, N=1e-3, B=2e-4, sinusoid=(0.02, 3.3), seed=11)
    b = imunoise.simulate(n, FS, N=2e-3, gm=[(5e-3, 30.0)], seed=12)
    return imunoise.fit(imunoise.adev(np.column_stack([a, b]), FS, taus=20))


def test_terms_are_the_components(model):
    assert len(model.terms) == model.channels == 2
    parts = model.components
    for c, terms in enumerate(model.terms):
        for term in terms:
            assert isinstance(term, noise.Term)
            if isinstance(term, noise.White):
                assert term.N == parts.N[c] and term.N_std == parts.N_std[c]
            elif isinstance(term, noise.Flicker):
                assert term.B == parts.B[c]
            elif isinstance(term, noise.GaussMarkov):
                assert (term.sigma, term.tau_c) in parts.gauss_markov(c)
            elif isinstance(term, noise.Tone):
                assert (term.amplitude, term.freq) in parts.sine(c)
        ieee = [t.name for t in terms if isinstance(t, noise.White | noise.Flicker
                                                     | noise.RandomWalk | noise.Quantization
                                                     | noise.Ramp)]
        assert ieee == [k for k in noise.TERMS if parts.supported[k][c]]
    assert any(isinstance(t, noise.Tone) and abs(t.freq / 3.3 - 1) < 0.01
               for t in model.terms[0]), model.terms[0]
    assert any(isinstance(t, noise.GaussMarkov) for t in model.terms[1]), model.terms[1]


def test_terms_add_up_to_the_model_curve(model):
    taus = np.geomspace(0.01, 300, 40)
    total = model.predict(taus).dev
    for c, terms in enumerate(model.terms):
        summed = sum(term.allan_variance(taus, model.fs) for term in terms)
        np.testing.assert_allclose(np.sqrt(summed), total[:, c], rtol=1e-12)


def test_uncertainties_are_finite_and_positive(model):
    for terms in model.terms:
        for term in terms:
            stds = [getattr(term, f) for f in map(attrgetter("name"), fields(term))
                    if f.endswith("_std")]
            assert all(math.isfinite(s) and s > 0 for s in stds), term


def test_terms_round_trip_through_the_core():
    kinds = {name: params for name, params, _ in core_fit.TERM_KINDS}
    terms = [noise.White(1e-3), noise.GaussMarkov(2e-3, 4.0), noise.Tone(0.01, 7.0),
             noise.Resonance(0.02, 12.0, 0.05, skew=0.3), noise.Motion(1e-4, 2.0)]
    for term in terms:
        kind, params = term.core()
        assert len(params) == len(kinds[kind])
        back = type(term).from_core(params, np.zeros((len(params), len(params))))
        for f in map(attrgetter("name"), fields(term)):
            if not f.endswith("_std"):
                assert getattr(back, f) == pytest.approx(getattr(term, f), rel=1e-15)
    assert repr(noise.White(1e-3)) == "White(N=0.001)"


def test_a_bad_term_is_refused_by_the_core():
    with pytest.raises(imunoise.ImunoiseValueError, match="tau_c must be finite and > 0"):
        noise.GaussMarkov(1.0, -2.0).allan_variance([1.0], FS)
    with pytest.raises(imunoise.ImunoiseValueError, match="skew must be in"):
        noise.Resonance(1.0, 5.0, 0.1, skew=2.0).allan_variance([1.0], FS)


def test_components_is_a_deprecated_view_of_the_terms(model):
    with pytest.warns(imunoise.ImunoiseDeprecationWarning, match="use model.terms"):
        parts = model.components
    assert parts.structure(1) == " + ".join(t.label() for t in model.terms[1])


def test_the_library_reads_terms_not_the_deprecated_view(model, tmp_path):
    """Tables, repr, exports, the planner and simulate(like=) never warn."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", imunoise.ImunoiseDeprecationWarning)
        repr(model), model._repr_html_(), model.table_text("gyro"), model.to_dict()
        imunoise.export.ekf_dict(gyro=model)
        imunoise.spectrum.model_psd(model, np.array([0.1, 1.0, 10.0]))
        imunoise.simulate(1000, None, like=model, seed=1)
        imunoise.plan(model, sensor="gyro")


def test_a_requested_term_the_data_put_at_zero_is_said_not_lost():
    x = imunoise.simulate(100_000, FS, N=1e-3, seed=4)
    r = imunoise.adev(x, FS, taus=10)
    with pytest.warns(imunoise.CoverageWarning, match=r"channel 0: B\b"):
        m = imunoise.fit(r, terms=["N", "B", "K"])
    labels = [t.label() for t in m.terms[0]]
    assert "B" not in labels and labels[0] == "N"
    assert any("requested B" in note and "came out at 0" in note for note in m.notes[0])
    # every requested term placed: no note, no warning
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", imunoise.CoverageWarning)
        full = imunoise.fit(r, terms=["N"])
    assert not any("requested" in note for note in full.notes[0])


def test_fit_asks_for_each_kind_by_its_class_name_and_the_core_checks_the_counts():
    from imunoise._core import fit as core_fit
    from imunoise.noise import _typed

    x = imunoise.simulate(20_000, 50.0, N=1e-3, seed=4)
    r = imunoise.adev(x, 50.0)
    most = dict(core_fit.TERM_MOST)
    assert set(most) == set(_typed.KINDS)
    assert most["gauss_markov"] == imunoise.noise.GM_MAX
    assert most["tone"] == imunoise.noise.TONES_MAX
    with pytest.raises(ValueError, match=r"every other name at most once; got \['N', 'N'\]"):
        imunoise.fit(r, terms=["N", "N"])
    t, v, e = (np.ascontiguousarray(a, dtype=float) for a in (r.taus, r.var, r.edf))
    with pytest.raises(ValueError, match="at most 1 white term"):
        core_fit.fit_noise(t, v, e, 50.0, [("white", 2)], False)
    with pytest.raises(ValueError, match="term kind must be one of"):
        core_fit.fit_noise(t, v, e, 50.0, [("pink", 1)], False)
    fitted = core_fit.fit_noise(t, v, e, 50.0, [("white", 1)], False)
    assert [kind for kind, _ in fitted.terms] == ["white"]
