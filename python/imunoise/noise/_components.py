"""The fitted components of a noise model: what the fit estimated, term by term.

A :class:`~imunoise.noise.NoiseModel` speaks in datasheet values (``model.N`` is
the white-noise density a datasheet quotes from the curve, whichever components
produce it); its :attr:`~imunoise.noise.NoiseModel.components` are the pieces
behind those values — the IEEE coefficients of the fit, the Gauss–Markov terms,
the tone, the resonance and a bounded motion of the mount — for simulation,
Kalman-filter states and diagnosis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from imunoise._support import schema as _schema
from imunoise._support import summary as _summary
from imunoise.errors import ImunoiseValueError
from imunoise.noise._terms import GM_MAX, TERMS, TONES_MAX, term_variances


def check_term(term: str) -> None:
    if term not in TERMS:
        raise ImunoiseValueError(f"term must be one of {TERMS}; got {term!r}")


@dataclass(frozen=True, repr=False)
class PerTerm:
    """What :class:`Components` and the model share: the values ``Q``…``R``, their
    ``*_std`` (arrays of shape () for one channel or (channels,)), which are
    ``supported``, and their accessors."""

    Q: np.ndarray
    N: np.ndarray
    B: np.ndarray
    K: np.ndarray
    R: np.ndarray
    Q_std: np.ndarray
    N_std: np.ndarray
    B_std: np.ndarray
    K_std: np.ndarray
    R_std: np.ndarray
    supported: dict[str, np.ndarray]

    @property
    def channels(self) -> int:
        """Number of channels (1 for a one-channel fit)."""
        return 1 if np.ndim(self.N) == 0 else int(np.shape(self.N)[0])

    @property
    def one_channel(self) -> bool:
        """True when fitted to a 1-D result (values are 0-d arrays)."""
        return np.ndim(self.N) == 0

    def value(self, term: str) -> np.ndarray:
        """``term`` (one of Q, N, B, K, R) as an array of shape (channels,)."""
        check_term(term)
        return np.atleast_1d(getattr(self, term))

    def std(self, term: str) -> np.ndarray:
        """Standard uncertainty of ``term``, shape (channels,)."""
        check_term(term)
        return np.atleast_1d(getattr(self, term + "_std"))


@dataclass(frozen=True, repr=False)
class Prediction:
    """Model Allan deviation: the total curve and each term's curve.

    ``dev`` and every ``terms[name]`` have shape (len(taus),) for a one-channel
    model and (len(taus), channels) otherwise. ``terms`` has ``Q``…``R`` and,
    when a channel has Gauss–Markov terms, ``GM1`` and ``GM2`` (0 where absent).
    """

    taus: np.ndarray
    dev: np.ndarray
    terms: dict[str, np.ndarray]

    @property
    def channels(self) -> int:
        """Number of channels (1 for a one-channel model)."""
        return 1 if np.ndim(self.dev) == 1 else int(np.shape(self.dev)[1])

    def _facts(self) -> list[str]:
        drawn = [k for k, v in self.terms.items() if np.any(np.asarray(v) > 0)]
        return [_summary.plural(self.channels, "channel"), _summary.tau_span(self.taus),
                "terms " + (" ".join(drawn) or "none")]

    def __repr__(self) -> str:
        return _summary.lines("Prediction(", self._facts(), sep=", ")

    def _repr_html_(self) -> str:
        """Per channel: the model deviation at the first and last tau and its minimum."""
        header, rows = _summary.curve_rows(self.taus, self.dev,
                                           _schema.axis_names(self.channels))
        return _summary.html_table(header, rows,
                                   caption="Prediction: " + ", ".join(self._facts()))


@dataclass(frozen=True, repr=False)
class Components(PerTerm):
    """The fitted components of a noise model, per channel, in the input's units.

    These are the fit's own parameters. The datasheet values a user quotes are
    the model's ``N``, ``B``, ``K``, ``Q``, ``R``, computed from all of these
    together (e.g. a Gauss–Markov term whose hump lies before 1 s adds to the white-noise
    density N; see :class:`~imunoise.noise.NoiseModel`). All arrays are read-only.

    Attributes
    ----------
    Q, N, B, K, R : ndarray
        IEEE 952 coefficients of the fit: rate·s, rate·√s, rate, rate/√s, rate/s.
        Shape () for a one-channel result, (channels,) otherwise; 0 where the
        term is not in the fitted structure.
    Q_std, N_std, B_std, K_std, R_std : ndarray
        Their standard uncertainties (NaN where the term is not in the structure).
    supported : dict[str, ndarray of bool]
        Whether each IEEE coefficient is in the fitted structure.
    tau_range : dict[str, ndarray]
        For each IEEE coefficient, (..., 2) array of the smallest and largest
        fitted τ where it is at least 25 % of the model (``"wls"``) or the
        tangent τ (``"slopes"``); NaN when not in the structure.
    gm_sigma, gm_tau : ndarray
        First-order Gauss–Markov bias terms: standard deviation (rate) and
        correlation time (s), shape (3,) or (channels, 3), by increasing τc;
        NaN in unused slots.
    gm_sigma_std, gm_tau_std : ndarray
        Their standard uncertainties.
    sine_amplitude, sine_freq : ndarray
        Tones A·sin(2πf0·t + ϕ): peak amplitude (rate) and frequency (Hz), shape
        (2,) or (channels, 2), by increasing frequency; NaN in unused slots.
    sine_amplitude_std, sine_freq_std : ndarray
        Their standard uncertainties.
    resonance_sigma, resonance_freq, resonance_tau, resonance_skew : ndarray
        A damped oscillator (second-order Gauss–Markov process, autocovariance
        σ²·ρ^|h|·(cos θh + s·κ·sin θ|h|), θ = 2πf_r/fs, ρ = exp(−1/(fs·τr)),
        κ = sinh(1/(fs·τr))/sin θ): standard deviation (rate), frequency f_r (Hz),
        damping time τr (s; quality factor π·f_r·τr) and skew s in [−1, 1], its
        quadrature part; NaN where a channel has none. s = 0 is the plain
        resonance; a sensor's own second-order low-pass filter has s > 0 (a
        digital Butterworth filter s = 1, Q = ½); at s = ±1 the spectrum touches
        zero at fs/2 (+1, a low-pass filter's zero) or at 0 Hz (−1, the rate of a
        bounded oscillation).
    resonance_sigma_std, resonance_freq_std, resonance_tau_std, resonance_skew_std : ndarray
        Their standard uncertainties (the frequency's is NaN when it sits on the
        fs/2 bound of the search, the skew's when it is ±1).
    motion_sigma, motion_tau : ndarray
        A bounded motion of the mount: its angle (velocity, for an accelerometer)
        wanders as a Gauss–Markov process of standard deviation σθ (rate·s) and
        correlation time τc (s) and comes back, and the sensor measures its rate —
        a parked vehicle rocking, a building swaying. Its Allan variance
        σθ²(3 − 4e^(−τ/τc) + e^(−2τ/τc))/τ² is white below τc (density 2σθ²/τc)
        and falls as 1/τ beyond: the −½ slope that steepens to −1. NaN where a
        channel has none. It is the platform's, not the sensor's: the datasheet
        values leave it out of N and K.
    motion_sigma_std, motion_tau_std : ndarray
        Their standard uncertainties.
    cov : ndarray
        ``"wls"``: covariance of (Q², N², B², K², R², then σ², ln τc of each
        Gauss–Markov slot, then A²/2, ln f0 of each tone slot, then σ², ln f_r,
        ln τr, skew of the resonance, then σθ², ln τc of the motion), shape (21, 21) or
        (channels, 21, 21); NaN for ``"slopes"``.
    fs : float
        Sample rate of the data (Hz): the terms' sampled forms depend on it.
    """

    tau_range: dict[str, np.ndarray]
    gm_sigma: np.ndarray
    gm_tau: np.ndarray
    gm_sigma_std: np.ndarray
    gm_tau_std: np.ndarray
    sine_amplitude: np.ndarray
    sine_freq: np.ndarray
    sine_amplitude_std: np.ndarray
    sine_freq_std: np.ndarray
    resonance_sigma: np.ndarray
    resonance_freq: np.ndarray
    resonance_tau: np.ndarray
    resonance_skew: np.ndarray
    resonance_sigma_std: np.ndarray
    resonance_freq_std: np.ndarray
    resonance_tau_std: np.ndarray
    resonance_skew_std: np.ndarray
    motion_sigma: np.ndarray
    motion_tau: np.ndarray
    motion_sigma_std: np.ndarray
    motion_tau_std: np.ndarray
    cov: np.ndarray
    fs: float

    def gauss_markov(self, channel: int = 0) -> list[tuple[float, float]]:
        """The (sigma, tau_c) of each Gauss–Markov term of ``channel``."""
        sig = np.reshape(self.gm_sigma, (-1, GM_MAX))[channel]
        tau = np.reshape(self.gm_tau, (-1, GM_MAX))[channel]
        return [(float(s), float(t)) for s, t in zip(sig, tau, strict=True) if np.isfinite(s)]

    def sine(self, channel: int = 0) -> list[tuple[float, float]]:
        """The (amplitude, f0) of each tone of ``channel``."""
        amp = np.reshape(self.sine_amplitude, (-1, TONES_MAX))[channel]
        f0 = np.reshape(self.sine_freq, (-1, TONES_MAX))[channel]
        return [(float(a), float(f)) for a, f in zip(amp, f0, strict=True) if np.isfinite(a)]

    def resonance(self, channel: int = 0) -> list[tuple[float, float, float, float]]:
        """The (sigma, f_r, tau_r, skew) of the resonance of ``channel``: one, or none."""
        sigma, f_r, tau_r, skew = (float(np.atleast_1d(a)[channel]) for a in
                                   (self.resonance_sigma, self.resonance_freq,
                                    self.resonance_tau, self.resonance_skew))
        return [(sigma, f_r, tau_r, skew)] if np.isfinite(sigma) else []

    def motion(self, channel: int = 0) -> list[tuple[float, float]]:
        """The (sigma, tau_c) of the bounded motion of ``channel``: one pair, or none."""
        sigma, tau_c = (float(np.atleast_1d(a)[channel]) for a in
                        (self.motion_sigma, self.motion_tau))
        return [(sigma, tau_c)] if np.isfinite(sigma) else []

    def count(self, channel: int = 0) -> int:
        """Number of terms in the fitted structure of ``channel`` (IEEE
        coefficients, Gauss–Markov terms, tone, resonance, bounded motion)."""
        ieee = sum(bool(np.atleast_1d(self.supported[t])[channel]) for t in TERMS)
        return (ieee + len(self.gauss_markov(channel)) + len(self.sine(channel))
                + len(self.resonance(channel)) + len(self.motion(channel)))

    def structure(self, channel: int = 0) -> str:
        """The fitted structure of ``channel`` in words: ``"N + K + GM(0.05 s) +
        tone 13.4 Hz"`` (``"none"`` when empty)."""
        parts = [t for t in TERMS if bool(np.atleast_1d(self.supported[t])[channel])]
        parts += [f"GM({_summary.number(tc)} s)" for _, tc in self.gauss_markov(channel)]
        parts += [f"tone {_summary.number(f0)} Hz" for _, f0 in self.sine(channel)]
        parts += [f"resonance {_summary.number(f)} Hz" + (f" (skew {skew:.2g})" if skew else "")
                  for _, f, _, skew in self.resonance(channel)]
        parts += [f"motion({_summary.number(tc)} s)" for _, tc in self.motion(channel)]
        return " + ".join(parts) or "none"

    def predict(self, taus) -> Prediction:
        """Allan deviation of the components at ``taus``: the total curve and each
        term's own curve (``terms["N"]`` = N/√τ, ``terms["GM1"]``, ``terms["sine"]``
        for the tones together, ``terms["resonance"]``, ``terms["motion"]``)."""
        t = np.asarray(taus, dtype=float)
        if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)) or np.any(t <= 0):
            raise ImunoiseValueError(
                f"taus must be a non-empty 1-D array of finite values > 0; got {t!r}")
        gm_names = [f"GM{k + 1}" for k in range(GM_MAX)]
        names = [*TERMS, *gm_names, "sine", "resonance", "motion"]
        parts = np.zeros((t.size, len(names), self.channels))
        for c in range(self.channels):
            markov, tone, osc = self.gauss_markov(c), self.sine(c), self.resonance(c)
            moving = self.motion(c)
            var = term_variances(t, self.fs, [self.value(k)[c] for k in TERMS], markov, tone, osc,
                                 moving)
            cols = [*range(len(TERMS) + len(markov)), *[names.index("sine")] * len(tone),
                    *([names.index("resonance")] if osc else []),
                    *([names.index("motion")] if moving else [])]
            np.add.at(parts[:, :, c], (slice(None), cols), var)
        total = np.sqrt(parts.sum(axis=1))
        channels = range(self.channels)
        used = [*TERMS, *gm_names[: max(len(self.gauss_markov(c)) for c in channels)],
                *(["sine"] if any(self.sine(c) for c in channels) else []),
                *(["resonance"] if any(self.resonance(c) for c in channels) else []),
                *(["motion"] if any(self.motion(c) for c in channels) else [])]
        terms = {k: np.sqrt(parts[:, names.index(k), :]) for k in used}
        if self.one_channel:
            total = total[:, 0]
            terms = {k: v[:, 0] for k, v in terms.items()}
        return Prediction(taus=t, dev=total, terms=terms)

    def other_terms(self) -> list[tuple[str, str, str | None, np.ndarray, np.ndarray]]:
        """(term, quantity, unit — None for a rate, ``"Q"`` for Q's unit (rate·s) —,
        values, stds per channel) of each row of the non-IEEE terms that any axis has."""
        out = []
        sig = np.reshape(self.gm_sigma, (self.channels, GM_MAX))
        sig_std = np.reshape(self.gm_sigma_std, (self.channels, GM_MAX))
        tau = np.reshape(self.gm_tau, (self.channels, GM_MAX))
        tau_std = np.reshape(self.gm_tau_std, (self.channels, GM_MAX))
        for k in range(GM_MAX):
            if np.isfinite(sig[:, k]).any():
                out.append((f"σ{k + 1}", "Gauss–Markov bias", None, sig[:, k],
                            sig_std[:, k]))
                out.append((f"τc{k + 1}", "Gauss–Markov correlation time", "s", tau[:, k],
                            tau_std[:, k]))
        tones = [np.reshape(a, (self.channels, TONES_MAX)) for a in (
            self.sine_amplitude, self.sine_amplitude_std, self.sine_freq, self.sine_freq_std)]
        used = [k for k in range(TONES_MAX) if np.isfinite(tones[0][:, k]).any()]
        for k in used:
            tag = str(k + 1) if len(used) > 1 else ""
            amp, amp_std, f0, f0_std = (a[:, k] for a in tones)
            out.append((f"A{tag}", "tone amplitude", None, amp, amp_std))
            out.append((f"f{tag}" if tag else "f0", "tone frequency", "Hz", f0, f0_std))
        one = np.atleast_1d
        if np.isfinite(one(self.resonance_sigma)).any():
            out.append(("σr", "resonance standard deviation", None, one(self.resonance_sigma),
                        one(self.resonance_sigma_std)))
            out.append(("f_r", "resonance frequency", "Hz", one(self.resonance_freq),
                        one(self.resonance_freq_std)))
            out.append(("τr", "resonance damping time", "s", one(self.resonance_tau),
                        one(self.resonance_tau_std)))
            skew = one(self.resonance_skew)
            if np.any(np.isfinite(skew) & (skew != 0)):
                out.append(("s_r", "resonance skew", "", skew, one(self.resonance_skew_std)))
        if np.isfinite(one(self.motion_sigma)).any():
            out.append(("σθ", "bounded motion (angle)", "Q", one(self.motion_sigma),
                        one(self.motion_sigma_std)))
            out.append(("τm", "bounded motion correlation time", "s", one(self.motion_tau),
                        one(self.motion_tau_std)))
        return out

    def to_dict(self) -> dict:
        """Plain-Python view (lists and floats), e.g. for JSON."""
        d: dict = {}
        for term in TERMS:
            d[term] = {
                "value": self.value(term).tolist(),
                "std": finite_list(self.std(term)),
                "supported": np.atleast_1d(self.supported[term]).tolist(),
                "tau_range": [finite_list(pair)
                              for pair in np.reshape(self.tau_range[term], (-1, 2))],
            }
        channels = range(self.channels)
        d["gauss_markov"] = [[{"sigma": sg, "tau_c": tc} for sg, tc in self.gauss_markov(c)]
                             for c in channels]
        d["sine"] = [[{"amplitude": a, "frequency": f0} for a, f0 in self.sine(c)]
                     for c in channels]
        d["resonance"] = [[{"sigma": sg, "frequency": f, "tau_r": tr, "skew": skew}
                           for sg, f, tr, skew in self.resonance(c)] for c in channels]
        d["motion"] = [[{"sigma": sg, "tau_c": tc} for sg, tc in self.motion(c)]
                       for c in channels]
        return d

    def __repr__(self) -> str:
        names = _schema.axis_names(self.channels)
        axes = [self.structure(c) if self.one_channel else f"{names[c]}: {self.structure(c)}"
                for c in range(self.channels)]
        return _summary.lines(f"Components({_summary.plural(self.channels, 'channel')}",
                              axes)

    def _repr_html_(self) -> str:
        """One row per axis: the fitted IEEE coefficients ± their uncertainty (— where
        not in the structure) and the structure in words."""
        rows = [[name, *(_summary.estimate(self.value(t)[c], self.std(t)[c])
                         if np.atleast_1d(self.supported[t])[c] else "—" for t in TERMS),
                 self.structure(c)]
                for c, name in enumerate(_schema.axis_names(self.channels))]
        return _summary.html_table(
            ["axis", *TERMS, "structure"], rows,
            caption=f"Components: {_summary.plural(self.channels, 'channel')}")


def finite_list(values) -> list[float | None]:
    """``values`` as a list of floats, ``None`` where not finite (JSON has no NaN)."""
    return [float(v) if np.isfinite(v) else None for v in np.atleast_1d(values)]
