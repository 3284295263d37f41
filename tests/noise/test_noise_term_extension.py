"""A kind of term is written and exported by its class alone: the report's
sentences and the EKF export iterate ``model.terms`` and ask each term for its
clause (``describe``, ``remark``) and its part of the filter's model (``ekf``), so
a class neither of them names flows through both. Neither needs the Rust core to
know the kind (only the Allan variance does), so a class defined here is enough."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import ClassVar

import imunoise
import pytest
from imunoise import export, noise, units
from imunoise.noise._ekf import BiasState, EkfShare
from imunoise.report.model_text import model_sentences

FS = 40.0

# A white-noise model resolves neither B nor K: the export writes their bounds and
# says so, which is not what these tests are about.
pytestmark = pytest.mark.filterwarnings("ignore::imunoise.CoverageWarning")


@dataclass(frozen=True, repr=False)
class Drift(noise.Term):
    """A kind the library does not have: its own words and its own EKF state."""

    kind: ClassVar[str] = "drift"
    noun: ClassVar[str] = "thermal drift"
    requested: ClassVar[str] = "drift"
    sigma: float
    tau_c: float

    def label(self) -> str:
        return f"drift({self.tau_c:g} s)"

    def describe(self, words) -> str:
        return (f"a thermal drift of {words.amount(self.sigma, None, 'B')} over "
                f"{words.number(self.tau_c)} s")

    def remark(self, words) -> str:
        return "the drift's remark"

    def ekf(self, fs: float, min_samples: float) -> EkfShare:
        return EkfShare(white_density=self.sigma**2 / fs,
                        states=(BiasState(self.sigma, self.tau_c),))


@dataclass(frozen=True, repr=False)
class Plain(noise.Term):
    """A kind that only names itself: the base class's defaults."""

    kind: ClassVar[str] = "plain"
    noun: ClassVar[str] = "plain wander"
    requested: ClassVar[str] = "plain"
    tau_c: float

    def label(self) -> str:
        return f"plain({self.tau_c:g} s)"


@pytest.fixture(scope="module")
def white():
    """A white-noise channel whose fit resolves N: the sentence reads N off it."""
    x = imunoise.simulate(100_000, FS, N=1e-3, seed=5)
    return imunoise.fit(imunoise.adev(x, FS, taus=10), terms=["N"], warn_coverage=False)


def with_terms(model, *extra):
    return replace(model, terms=tuple(terms + extra for terms in model.terms))


def test_a_new_kinds_clause_is_its_own_in_the_sentence(white):
    drift = Drift(sigma=2e-4, tau_c=40.0)
    (before,) = model_sentences(white, "gyro")
    (sentence,) = model_sentences(with_terms(white, drift), "gyro")
    assert sentence.startswith("value: fitted components N + drift(40 s);")
    shown = float(units.convert(drift.sigma, "B", "deg/h", sensor="gyro"))
    clause = f"a thermal drift of {imunoise.display.cell(shown, None, digits=6)} °/h over 40 s"
    # the term's clause after the coverage, its remark after every term's clause;
    # the rest of the sentence as without it
    assert f"; {clause}; the drift's remark; " in sentence
    assert sentence.replace(" + drift(40 s)", "").replace(
        f"; {clause}; the drift's remark", "") == before


def test_a_new_kinds_state_and_white_noise_reach_the_ekf_export(white):
    drift = Drift(sigma=2e-4, tau_c=40.0)
    plain = export.ekf_dict(gyro=white)["gyroscope"]["axes"]["ch0"]
    axis = export.ekf_dict(gyro=with_terms(white, drift))["gyroscope"]["axes"]["ch0"]
    assert axis["gauss_markov"] == [{
        "sigma": drift.sigma, "correlation_time": drift.tau_c,
        "driving_noise_density": drift.sigma * math.sqrt(2.0 / drift.tau_c)}]
    assert axis["white_noise_density"] == pytest.approx(
        math.sqrt(plain["white_noise_density"] ** 2 + drift.sigma**2 / FS), rel=1e-12)
    text = export.ekf_yaml(gyro=with_terms(white, drift))
    assert "correlation_time: 4.000000e+01" in text


def test_a_kind_without_words_or_state_is_named_and_left_out_of_the_filter(white):
    term = Plain(tau_c=3.0)
    (sentence,) = model_sentences(with_terms(white, term), "gyro")
    assert "; plain wander: plain(3 s);" in sentence
    assert export.ekf_dict(gyro=with_terms(white, term)) == export.ekf_dict(gyro=white)


def test_every_kind_writes_and_exports_through_its_class(white, monkeypatch):
    """The kinds the library has: patch each class's methods and the report and
    the export say what the class says, nothing of their own."""
    for cls in noise._typed.KINDS.values():
        monkeypatch.setattr(cls, "describe", lambda self, words: f"<{self.kind}>")
        monkeypatch.setattr(cls, "remark", lambda self, words: None)
        monkeypatch.setattr(cls, "ekf", lambda self, fs, n: EkfShare(white_density=1.0))
    terms = (noise.GaussMarkov(1e-4, 0.02), noise.Tone(1e-3, 3.0),
             noise.Resonance(1e-3, 9.0, 0.2, 0.5), noise.Motion(1e-5, 20.0))
    model = replace(white, terms=(white.terms[0] + terms,))
    (sentence,) = model_sentences(model, "gyro")
    assert "; <white>; <gauss_markov>; <tone>; <resonance>; <motion>; " in sentence
    axis = export.ekf_dict(gyro=model)["gyroscope"]["axes"]["ch0"]
    assert axis["white_noise_density"] == pytest.approx(math.sqrt(5.0))
    assert axis["gauss_markov"] == []


def test_predict_and_the_allan_panel_name_each_curve_by_its_class(monkeypatch):
    import matplotlib

    matplotlib.use("Agg")
    import numpy as np

    x = imunoise.simulate(200_000, FS, N=1e-3, gm=[(2e-3, 20.0)], seed=3)
    r = imunoise.adev(x, FS, taus=10)
    model = imunoise.fit(r, terms=["N", "GM"], warn_coverage=False)
    monkeypatch.setattr(noise.GaussMarkov, "curve", lambda self, index: f"wander {index}")
    pred = model.predict()
    assert "wander 0" in pred.terms and "GM1" not in pred.terms
    np.testing.assert_allclose(pred.terms["wander 0"] ** 2 + pred.terms["N"] ** 2,
                               pred.dev**2, rtol=1e-12)
    fig = model.plot(r)
    labels = [line.get_label() for ax in fig.axes for line in ax.get_lines()]
    assert "wander 0" in labels
