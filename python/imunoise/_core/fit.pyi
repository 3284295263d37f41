# rust/bindings/fit.rs: the noise-model fit.

from typing import final

import numpy as np
import numpy.typing as npt

IEEE_TERM_NAMES: list[str]
"""The IEEE 952 coefficients in array order: Q, N, B, K, R."""
MAX_GAUSS_MARKOV: int
"""Most first-order Gauss–Markov terms a model may have."""
MAX_TONES: int
"""Most tones a model may have."""
PARAMETERS: int
"""Slots of the covariance: Q²…R², then (q², ln τc) per Gauss–Markov term, then
(s², ln f₀) per tone slot, then (r², ln f_r, ln τr, skew) of the resonance, then
(σθ², ln τc) of the bounded motion."""
SINE_SLOT: int
"""Slot of the first tone's variance s² (its ln f₀ follows, then the next tone's)."""
RESONANCE_SLOT: int
"""Slot of the resonance's variance r² (its ln f_r, ln τr, skew follow)."""
SKEW_SLOT: int
"""Slot of the resonance's skew in [−1, 1], its quadrature part."""
MOTION_SLOT: int
"""Slot of the bounded motion's variance σθ² (its ln τc follows)."""
FLICKER_FACTOR: float
"""(2 ln 2)/π: the Allan variance of flicker rate noise per unit B²."""

@final
class NoiseFit:
    """The fit of one channel."""

    @property
    def ieee(self) -> npt.NDArray[np.float64]:
        """(Q², N², B², K², R²)."""
    @property
    def gm(self) -> npt.NDArray[np.float64]:
        """(k, 2) rows of (q², τc), one per Gauss–Markov term."""
    @property
    def sine(self) -> npt.NDArray[np.float64]:
        """(k, 2) rows of (s², f₀), k ≤ MAX_TONES: the tones."""
    @property
    def resonance(self) -> npt.NDArray[np.float64]:
        """(k, 4) rows of (r², f_r, τr, skew), k ≤ 1: the resonance."""
    @property
    def motion(self) -> npt.NDArray[np.float64]:
        """(k, 2) rows of (σθ², τc), k ≤ 1: the bounded motion."""
    @property
    def cov(self) -> npt.NDArray[np.float64]:
        """(PARAMETERS, PARAMETERS) covariance of (Q²…R², then q², ln τc per slot,
        then s², ln f₀ per tone slot, then r², ln f_r, ln τr, skew, then σθ², ln τc; NaN
        variance of ln f_r at fs/2 and of the skew at ±1)."""
    @property
    def discrepancy(self) -> float:
        """δ, the relative model discrepancy."""
    @property
    def chi2(self) -> float:
        """Octave-weighted residual sum with the sampling variance alone."""
    @property
    def n_eff(self) -> float:
        """Octaves of evidence."""
    @property
    def parameters(self) -> int:
        """Free parameters of the chosen structure."""
    @property
    def bic(self) -> float:
        """Its Bayesian information criterion."""

def fit_noise(
    taus: npt.NDArray[np.float64],
    var: npt.NDArray[np.float64],
    edf: npt.NDArray[np.float64],
    fs: float,
    terms: list[bool],
    gm: int = 3,
    select: bool = True,
    tones: int = 2,
    resonance: bool = True,
    motion: bool = True,
    filter: npt.NDArray[np.float64] | None = None,
) -> NoiseFit:
    """Log-space, octave-weighted fit of the noise model (IEEE terms, up to
    ``gm`` Gauss–Markov terms, up to ``tones`` tones, with ``resonance`` a
    damped oscillator and with ``motion`` a bounded motion of the mount) to one
    channel; structure chosen by BIC when ``select``. ``filter``: the sensor's
    output-filter power gain G at L ≥ 2 frequencies evenly spaced from 0 Hz
    (G = 1) to fs/2; the white term is seen through it."""

def noise_terms(
    taus: npt.NDArray[np.float64],
    fs: float,
    ieee: list[float],
    gm: list[tuple[float, float]],
    sine: list[tuple[float, float]] = ...,
    resonance: list[tuple[float, float, float, float]] = ...,
    motion: list[tuple[float, float]] = ...,
    filter: npt.NDArray[np.float64] | None = None,
) -> npt.NDArray[np.float64]:
    """Allan variance of each model term at ``taus``: (len(taus), 5 + len(gm) +
    len(sine) + len(resonance) + len(motion)), ``sine`` as (s², f₀) pairs,
    ``resonance`` as (r², f_r, τr, skew) quadruples, ``motion`` as (σθ², τc) pairs."""

def filter_factor(
    taus: npt.NDArray[np.float64],
    fs: float,
    filter: npt.NDArray[np.float64],
) -> npt.NDArray[np.float64]:
    """c(τ): the white term's Allan variance through the output filter ``filter``
    (power gain from 0 Hz to fs/2, G(0) = 1) over the one without."""
