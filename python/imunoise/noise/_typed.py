"""The terms of a fitted noise model, typed: one class per kind, each holding its
own parameters and their standard uncertainties, in the input's units.

``model.terms[c]`` is channel ``c``'s tuple of terms in the order the model lists
them (the IEEE terms Q, N, B, K, R, then Gauss–Markov terms by increasing τc, tones
by increasing frequency, the resonance, the bounded motion). These are the fit's own
parameters; the datasheet values ``model.N``, ``model.B``, ``model.K`` are read from
all of them together (:class:`~imunoise.noise.NoiseModel`).

Each kind has its Rust counterpart (``rust/fit/term.rs``, exported as
``imunoise._core.fit.TERM_KINDS``): the Allan variance of every term comes from
there, the classes here name and convert its parameters, write the report's
clause on it (:meth:`Term.describe`) and say what it gives an EKF's model of its
channel (:meth:`Term.ekf`), so that the report and the export iterate
``model.terms`` without naming kinds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from imunoise._core import fit as _core_fit
from imunoise._support import summary as _summary
from imunoise.noise._ekf import BiasState, EkfShare
from imunoise.noise._terms import gm_white_density, resonance_white_density

if TYPE_CHECKING:
    from imunoise.report.term_words import TermWords


def _sigma(variance: float, u_variance: float) -> tuple[float, float]:
    """σ and u(σ) = u(σ²)/(2σ) from a variance and its variance."""
    sigma = math.sqrt(variance)
    if not (np.isfinite(u_variance) and sigma > 0):
        return sigma, math.nan
    return sigma, math.sqrt(max(u_variance, 0.0)) / (2.0 * sigma)


def _from_log(value: float, u_log: float) -> float:
    """u(x) = x·u(ln x); NaN where ln x is not free."""
    return value * math.sqrt(max(u_log, 0.0)) if np.isfinite(u_log) else math.nan


@dataclass(frozen=True)
class Term:
    """One term of a channel's noise model (the base of every kind)."""

    kind: ClassVar[str] = ""
    #: The kind in words, as a sentence names it: ``"rate random walk"``.
    noun: ClassVar[str] = ""
    #: The name ``fit(terms=[...])`` asks for this kind by.
    requested: ClassVar[str] = ""

    def core(self) -> tuple[str, list[float]]:
        """(kind, parameters) in the core's form (variances, times, frequencies)."""
        raise NotImplementedError

    def allan_variance(self, taus, fs: float) -> np.ndarray:
        """This term's Allan variance at ``taus`` (s) for data sampled at ``fs`` (Hz)."""
        t = np.ascontiguousarray(np.atleast_1d(np.asarray(taus, dtype=float)))
        return _core_fit.allan_terms(t, float(fs), [self.core()])[:, 0]

    def label(self) -> str:
        """The term in a structure's words: ``"N"``, ``"GM(0.05 s)"``, ``"tone 13.4 Hz"``."""
        raise NotImplementedError

    def curve(self, index: int) -> str:
        """The name of this term's curve in :meth:`NoiseModel.predict`, ``index`` its
        place among its channel's terms of the same kind (terms that share a name are
        drawn as one curve): its kind's name."""
        return self.kind

    def sample(self, n: int, fs: float, rng: np.random.Generator,
               channels: int = 1) -> np.ndarray:
        """``channels`` independent records, shape (n, channels), of this term's own
        process at ``fs`` (Hz): a model's record is the sum of its terms'."""
        from imunoise._simulation.simulate import simulate

        x = simulate(n, fs, channels=channels, seed=rng, **self._simulate())
        return x.reshape(n, channels)

    def _simulate(self) -> dict:
        """The keyword arguments of :func:`imunoise.simulate` that draw this term alone."""
        raise NotImplementedError

    def psd(self, f, fs: float) -> np.ndarray | None:
        """This term's one-sided PSD at ``f`` (Hz) for data sampled at ``fs`` (Hz);
        None for a tone, a line with no density (plots mark its frequency)."""
        raise NotImplementedError

    def describe(self, words: TermWords) -> str | None:
        """The report's clause on this term in one channel's sentence (``imunoise
        fit`` prints it too), written with ``words`` (the channel's units, spelling
        of numbers, spectral lines and N); None where the tables say it all. By
        default the kind's noun and the term's label (``"noun: label"``), so that a
        kind without words of its own is still named."""
        return f"{self.noun}: {self.label()}"

    def remark(self, words: TermWords) -> str | None:
        """A clause after every term's own (:meth:`describe`): what this term means
        for the model's other values. By default None."""
        return None

    def ekf(self, fs: float, min_samples: float) -> EkfShare:
        """This term's part of an extended Kalman filter's model of its channel
        (:func:`imunoise.export.ekf_dict`) at ``fs`` Hz, where a bias state needs a
        correlation time of at least ``min_samples`` samples.

        By default nothing: a kind whose noise an estimator should carry gives it
        here, as white noise or as bias states; any other is left out of the
        filter's model, as a tone (a deterministic line, which no bias state
        follows) and a bounded motion (the mount's, not the sensor's) are. Flicker
        and the rate random walk give nothing either: the export writes B and K
        from the model's datasheet values, beside the states."""
        return EkfShare()

    def to_dict(self) -> dict:
        """Plain-Python view: ``kind`` and every parameter and its ``*_std``
        (None where not finite: JSON has no NaN)."""
        out: dict = {"kind": self.kind}
        for f in fields(self):
            v = float(getattr(self, f.name))
            out[f.name] = v if math.isfinite(v) else None
        return out

    def __repr__(self) -> str:
        values = [f"{f.name}={getattr(self, f.name):.4g}" for f in fields(self)
                  if not f.name.endswith("_std")]
        return f"{type(self).__name__}({', '.join(values)})"


@dataclass(frozen=True, repr=False)
class _Ieee(Term):
    """An IEEE 952 term: one coefficient and its standard uncertainty."""

    name: ClassVar[str] = ""

    @property
    def value(self) -> float:
        """The coefficient (Q, N, B, K or R)."""
        return getattr(self, self.name)

    def core(self) -> tuple[str, list[float]]:
        return self.kind, [self.value**2]

    def label(self) -> str:
        return self.name

    def curve(self, index: int) -> str:
        return self.name

    def describe(self, words: TermWords) -> str | None:
        # The datasheet table and the read-off comparison say a coefficient.
        return None

    def _simulate(self) -> dict:
        return {self.name: self.value}

    def psd(self, f, fs: float) -> np.ndarray:
        from imunoise.spectrum import term_psd

        return term_psd(self.name, self.value, np.asarray(f, dtype=float), fs=fs)

    @classmethod
    def from_core(cls, parameters, cov):
        value, std = _sigma(parameters[0], cov[0, 0])
        return cls(value, std)


@dataclass(frozen=True, repr=False)
class Quantization(_Ieee):
    """Quantization noise: Allan variance 3Q²/τ², ``Q`` in rate·s."""

    kind: ClassVar[str] = "quantization"
    noun: ClassVar[str] = "quantization noise"
    name: ClassVar[str] = "Q"
    requested: ClassVar[str] = "Q"
    Q: float
    Q_std: float = math.nan


@dataclass(frozen=True, repr=False)
class White(_Ieee):
    """White rate noise (angle or velocity random walk): N²/τ, ``N`` in rate·√s."""

    kind: ClassVar[str] = "white"
    noun: ClassVar[str] = "white noise"
    name: ClassVar[str] = "N"
    requested: ClassVar[str] = "N"
    N: float
    N_std: float = math.nan

    def ekf(self, fs: float, min_samples: float) -> EkfShare:
        return EkfShare(white_density=self.N**2)


@dataclass(frozen=True, repr=False)
class Flicker(_Ieee):
    """Flicker rate noise (bias instability): (2 ln2/π)·B², ``B`` in rate."""

    kind: ClassVar[str] = "flicker"
    noun: ClassVar[str] = "flicker (bias instability)"
    name: ClassVar[str] = "B"
    requested: ClassVar[str] = "B"
    B: float
    B_std: float = math.nan


@dataclass(frozen=True, repr=False)
class RandomWalk(_Ieee):
    """Rate random walk: K²τ/3, ``K`` in rate/√s."""

    kind: ClassVar[str] = "random_walk"
    noun: ClassVar[str] = "rate random walk"
    name: ClassVar[str] = "K"
    requested: ClassVar[str] = "K"
    K: float
    K_std: float = math.nan


@dataclass(frozen=True, repr=False)
class Ramp(_Ieee):
    """Rate ramp: R²τ²/2, ``R`` in rate/s."""

    kind: ClassVar[str] = "ramp"
    noun: ClassVar[str] = "rate ramp"
    name: ClassVar[str] = "R"
    requested: ClassVar[str] = "R"
    R: float
    R_std: float = math.nan


@dataclass(frozen=True, repr=False)
class _VarianceAndTime(Term):
    """A term of a standard deviation ``sigma`` and a time ``tau_c`` (s): the core
    holds σ² and τc, its covariance σ² and ln τc (the Gauss–Markov term, the
    bounded motion)."""

    sigma: float
    tau_c: float
    sigma_std: float = math.nan
    tau_c_std: float = math.nan

    def core(self) -> tuple[str, list[float]]:
        return self.kind, [self.sigma**2, self.tau_c]

    def _ar1_psd(self, f, fs: float) -> np.ndarray:
        """One-sided PSD of the sampled AR1 of standard deviation σ and time τc:
        2σ²(1 − φ²)/fs / |1 − φe^(−iω)|², φ = e^(−1/(fs·τc)), ω = 2πf/fs."""
        phi = math.exp(-1.0 / (fs * self.tau_c))
        e = np.exp(-2j * np.pi * np.asarray(f, dtype=float) / fs)
        return 2 * self.sigma**2 * (1 - phi**2) / fs / np.abs(1 - phi * e) ** 2

    @classmethod
    def from_core(cls, parameters, cov):
        sigma, u_sigma = _sigma(parameters[0], cov[0, 0])
        return cls(sigma, parameters[1], u_sigma, _from_log(parameters[1], cov[1, 1]))


#: Share of the datasheet N² above which a Gauss–Markov term's white tail "carries" N.
CARRIES_N = 0.5


@dataclass(frozen=True, repr=False)
class GaussMarkov(_VarianceAndTime):
    """First-order Gauss–Markov bias: standard deviation ``sigma`` (rate) and
    correlation time ``tau_c`` (s); its Allan variance is the sampled AR1 form of
    IEEE 952 Annex C (rising as +½ below τc, a hump near 1.89 τc, −½ beyond)."""

    kind: ClassVar[str] = "gauss_markov"
    noun: ClassVar[str] = "Gauss–Markov bump"
    requested: ClassVar[str] = "GM"

    def label(self) -> str:
        return f"GM({_summary.number(self.tau_c)} s)"

    def curve(self, index: int) -> str:
        return f"GM{index + 1}"

    def describe(self, words: TermWords) -> str:
        return (f"Gauss–Markov bias σ = {words.amount(self.sigma, self.sigma_std, 'B')}, "
                f"τc = {words.number(self.tau_c, self.tau_c_std)} s")

    def remark(self, words: TermWords) -> str | None:
        """Where most of the datasheet N² is this term's white tail and the curve
        shows its hump (its peak, at ≈ 1.9 τc, beyond the first two taus): that N
        is the sensor's output filter or a disturbance of the mount, which the
        Allan curve cannot tell apart (a ring-laser gyro on a parked vehicle
        printed the vehicle's vibration as its angle random walk, 100× the gyro's
        own)."""
        n2 = words.n**2
        if not n2 > 0 or len(words.taus) < 3:
            return None
        share = gm_white_density(self.sigma, self.tau_c, words.fs) / n2
        if not (self.tau_c < 1.0 and share > CARRIES_N
                and 1.9 * self.tau_c > float(words.taus[1])):
            return None
        return (f"N is {words.percent(share)} the white tail of the Gauss–Markov term of "
                f"τc {self.tau_c:.2g} s, whose hump the curve shows near "
                f"{1.9 * self.tau_c:.2g} s: the sensor's own output filter, or a "
                "disturbance of the mount (a vehicle's or a machine's vibration), which "
                "the Allan deviation cannot tell apart; where the sensor's filter is "
                "faster, its own white noise lies below this N")

    def _simulate(self) -> dict:
        return {"gm": [(self.sigma, self.tau_c)]}

    def ekf(self, fs: float, min_samples: float) -> EkfShare:
        # Too fast to be a filter state at the IMU rate: white noise.
        if self.tau_c * fs < min_samples:
            return EkfShare(white_density=gm_white_density(self.sigma, self.tau_c, fs))
        return EkfShare(states=(BiasState(self.sigma, self.tau_c),))

    def psd(self, f, fs: float) -> np.ndarray:
        return self._ar1_psd(f, fs)


@dataclass(frozen=True, repr=False)
class Tone(Term):
    """A sinusoid A·sin(2πf₀t + ϕ): peak ``amplitude`` (rate) and ``freq`` f₀ (Hz).

    Fitted with a spectrum that shows its line, ``freq`` is the spectrum's and
    ``freq_std`` the Allan curve's uncertainty there (the spectrum's own is a
    fraction of its bin)."""

    kind: ClassVar[str] = "tone"
    noun: ClassVar[str] = "tone"
    requested: ClassVar[str] = "sine"
    amplitude: float
    freq: float
    amplitude_std: float = math.nan
    freq_std: float = math.nan

    def core(self) -> tuple[str, list[float]]:
        return self.kind, [self.amplitude**2 / 2, self.freq]

    def label(self) -> str:
        return f"tone {_summary.number(self.freq)} Hz"

    def curve(self, index: int) -> str:
        return "sine"  # the tones together: their sum is what the curve shows

    def describe(self, words: TermWords) -> str | None:
        """A line where the spectrum shows one, at the spectrum's frequency; a tone
        where no spectrum checked it; where the spectrum shows none, a shape of the
        Allan curve. None where the model has no spectral check of it."""
        line = words.line(self.freq)
        if line is None:
            return None
        amplitude = words.amount(line.amplitude, self.amplitude_std, "B")
        if line.in_spectrum is None:
            return (f"a tone of amplitude {amplitude} at "
                    f"{words.number(line.frequency, self.freq_std)} Hz "
                    "(not checked against a spectrum)")
        if line.in_spectrum:
            return (f"a line of amplitude {amplitude} at {line.frequency:.4g} Hz (the "
                    f"spectrum's peak, {words.three(line.ratio)}× its background)")
        return (f"the Allan curve bends like a tone near {line.allan_frequency:.3g} Hz, but "
                "the spectrum shows no line there: a shape of the sensor's filter or noise, "
                "not a vibration")

    def _simulate(self) -> dict:
        return {"sinusoid": [(self.amplitude, self.freq)]}

    def psd(self, f, fs: float) -> None:
        return None

    @classmethod
    def from_core(cls, parameters, cov):
        # s² = A²/2, so u(A) = u(s²)/A.
        amplitude = math.sqrt(2 * parameters[0])
        u = math.sqrt(max(cov[0, 0], 0.0)) / amplitude if np.isfinite(cov[0, 0]) else math.nan
        return cls(amplitude, parameters[1], u, _from_log(parameters[1], cov[1, 1]))


@dataclass(frozen=True, repr=False)
class Resonance(Term):
    """A damped oscillator (second-order Gauss–Markov process): standard deviation
    ``sigma`` (rate), frequency ``freq`` f_r (Hz), damping time ``tau`` τr (s;
    quality factor π·f_r·τr) and ``skew`` in [−1, 1], its quadrature part (0: the
    plain resonance; a sensor's second-order low-pass filter has skew > 0)."""

    kind: ClassVar[str] = "resonance"
    noun: ClassVar[str] = "resonance"
    requested: ClassVar[str] = "resonance"
    sigma: float
    freq: float
    tau: float
    skew: float = 0.0
    sigma_std: float = math.nan
    freq_std: float = math.nan
    tau_std: float = math.nan
    skew_std: float = math.nan

    def core(self) -> tuple[str, list[float]]:
        return self.kind, [self.sigma**2, self.freq, self.tau, self.skew]

    def label(self) -> str:
        skew = f" (skew {self.skew:.2g})" if self.skew else ""
        return f"resonance {_summary.number(self.freq)} Hz{skew}"

    def describe(self, words: TermWords) -> str:
        text = (f"a resonance (damped oscillation, a band rather than a line) of "
                f"σ = {words.amount(self.sigma, self.sigma_std, 'B')} at "
                f"{words.number(self.freq, self.freq_std)} Hz, damping time "
                f"{words.number(self.tau, self.tau_std)} s (quality factor "
                f"{math.pi * self.freq * self.tau:.2g})")
        if not self.skew:
            return text
        shape = (" — the shape of a second-order low-pass filter, as a sensor's own output "
                 "filter is" if self.skew > 0 else "")
        return text + f", skew {words.number(self.skew, self.skew_std)}{shape}"

    def _simulate(self) -> dict:
        return {"resonance": (self.sigma, self.freq, self.tau, self.skew)}

    def ekf(self, fs: float, min_samples: float) -> EkfShare:
        # Like a tone, no bias state; what it adds to the white floor (its
        # spectrum at zero frequency) is measurement noise.
        return EkfShare(white_density=resonance_white_density(self.sigma, self.freq,
                                                              self.tau, fs, self.skew))

    def psd(self, f, fs: float) -> np.ndarray:
        from imunoise.spectrum import resonance_psd

        return resonance_psd(self.sigma, self.freq, self.tau, self.skew, f, fs)

    @classmethod
    def from_core(cls, parameters, cov):
        sigma, u_sigma = _sigma(parameters[0], cov[0, 0])
        u_skew = math.sqrt(max(cov[3, 3], 0.0)) if np.isfinite(cov[3, 3]) else math.nan
        return cls(sigma, parameters[1], parameters[2], parameters[3], u_sigma,
                   _from_log(parameters[1], cov[1, 1]), _from_log(parameters[2], cov[2, 2]),
                   u_skew)


@dataclass(frozen=True, repr=False)
class Motion(_VarianceAndTime):
    """A bounded motion of the mount: its angle (velocity, for an accelerometer)
    wanders as a Gauss–Markov process of standard deviation ``sigma`` (rate·s) and
    correlation time ``tau_c`` (s) and comes back; the platform's, not the sensor's."""

    kind: ClassVar[str] = "motion"
    noun: ClassVar[str] = "bounded motion"
    requested: ClassVar[str] = "motion"

    def label(self) -> str:
        return f"motion({_summary.number(self.tau_c)} s)"

    def describe(self, words: TermWords) -> str:
        """Its size and time, and that N leaves it out (where N is not resolved, an
        upper bound on it: the motion's own white density below τc)."""
        text = (f"**a bounded motion of the mount** (the platform's angle wanders by "
                f"σ = {words.amount(self.sigma, self.sigma_std, 'Q')} over "
                f"τc = {words.number(self.tau_c, self.tau_c_std)} s and comes back: white "
                "below τc, falling as 1/τ beyond) — not the sensor's noise, so N leaves it out")
        if words.n > 0:
            return text
        white = math.sqrt(2.0 * self.sigma**2 / self.tau_c)  # its density below τc
        return (text + "; under it the sensor's own white noise does not show: N is not "
                f"resolved, at most {words.amount(white, None, 'N')}")

    def _simulate(self) -> dict:
        return {"motion": (self.sigma, self.tau_c)}

    def psd(self, f, fs: float) -> np.ndarray:
        # the rate (θ[t] − θ[t−1])·fs of the angle's AR1: |1 − e^(−iω)|²·fs² = 4 sin²(ω/2)·fs²
        omega = 2 * np.pi * np.asarray(f, dtype=float) / fs
        return self._ar1_psd(f, fs) * (2 * fs * np.sin(omega / 2)) ** 2


#: Every kind, by the core's name, in the order a model lists them.
KINDS: dict[str, type[Term]] = {
    cls.kind: cls for cls in (Quantization, White, Flicker, RandomWalk, Ramp, GaussMarkov,
                              Tone, Resonance, Motion)
}

#: The IEEE kinds by coefficient name (Q, N, B, K, R).
IEEE: dict[str, type[_Ieee]] = {
    cls.name: cls for cls in (Quantization, White, Flicker, RandomWalk, Ramp)
}

#: Covariance coordinates per kind of term.
COORDINATES = {name: len(coords) for name, _, coords in _core_fit.TERM_KINDS}

#: The most terms of each kind a channel's model holds.
MOST = dict(_core_fit.TERM_MOST)


def from_core(core_terms, cov: np.ndarray) -> tuple[Term, ...]:
    """The typed terms of one channel's core fit: ``core_terms`` as (kind,
    parameters) pairs, ``cov`` the covariance of their coordinates, term after term."""
    out = []
    at = 0
    for kind, parameters in core_terms:
        width = COORDINATES[kind]
        out.append(KINDS[kind].from_core(parameters, cov[at:at + width, at:at + width]))
        at += width
    return tuple(out)


def allan_variances(terms, taus, fs: float) -> np.ndarray:
    """(len(taus), len(terms)): each term's Allan variance at ``taus``."""
    t = np.ascontiguousarray(np.atleast_1d(np.asarray(taus, dtype=float)))
    if not terms:
        return np.zeros((t.size, 0))
    return _core_fit.allan_terms(t, float(fs), [term.core() for term in terms])


def ieee_term(terms, name: str) -> _Ieee | None:
    """The IEEE term of coefficient ``name`` (Q, N, B, K or R) among one channel's
    terms, or None."""
    return next((t for t in terms if isinstance(t, _Ieee) and t.name == name), None)


def coefficient(terms, name: str) -> float:
    """The fitted IEEE coefficient ``name`` of one channel's terms; 0 where the
    structure has none."""
    term = ieee_term(terms, name)
    return 0.0 if term is None else term.value


def pairs(terms, cls: type[Term], *names: str) -> list[tuple[float, ...]]:
    """``names``' values of each term of class ``cls``, as tuples, in order."""
    return [tuple(float(getattr(t, n)) for n in names) for t in terms if isinstance(t, cls)]


def psd_parts(terms, f, fs: float) -> dict[str, np.ndarray]:
    """One channel's terms as one-sided PSDs at ``f``, by name: the ``fit(terms=...)``
    name, numbered where a model may hold several of the kind (``"N"``, ``"GM1"``,
    ``"resonance"``, ``"motion"``); tones, lines without a density, are left out."""
    out: dict[str, np.ndarray] = {}
    seen: dict[str, int] = {}
    for term in terms:
        density = term.psd(f, fs)
        if density is None:
            continue
        k = seen[term.kind] = seen.get(term.kind, 0) + 1
        name = term.requested + (str(k) if MOST[term.kind] > 1 else "")
        out[name] = density
    return out


def structure(terms) -> str:
    """One channel's fitted structure in words: ``"N + K + GM(0.05 s) + tone 13.4 Hz"``
    (``"none"`` when empty)."""
    return " + ".join(t.label() for t in terms) or "none"
