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
#: (kind, the most terms of it a model may have) per kind.
TERM_MOST: list[tuple[str, int]]
TERM_KINDS: list[tuple[str, list[str], list[str]]]
"""Every kind of term in the order a model lists them: (name, parameter names,
covariance coordinate names)."""
FLICKER_FACTOR: float
"""(2 ln 2)/π: the Allan variance of flicker rate noise per unit B²."""
GM_PEAK: float
"""τ/τc where a first-order Gauss–Markov term's Allan variance peaks (its hump)."""
FLAT_SLOPE: float
"""A deviation curve whose log-log slope is above this has flattened (B's floor)."""

@final
class NoiseFit:
    """The fit of one channel."""

    @property
    def terms(self) -> list[tuple[str, list[float]]]:
        """(kind, parameters) of each term, in the model's order."""
    @property
    def cov(self) -> npt.NDArray[np.float64]:
        """Covariance of the terms' coordinates, term after term (NaN variance for
        a coordinate on a bound)."""
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
    @property
    def ambiguous(self) -> list[tuple[str, str | None, float]]:
        """(kind, alternative kind, ΔBIC) of each term of a selected structure that
        the alternative fits as well: not resolved by the data."""

def fit_noise(
    taus: npt.NDArray[np.float64],
    var: npt.NDArray[np.float64],
    edf: npt.NDArray[np.float64],
    fs: float,
    counts: list[tuple[str, int]],
    select: bool = True,
    filter: npt.NDArray[np.float64] | None = None,
    filter_level_std: float = 0.0,
) -> NoiseFit:
    """Log-space, octave-weighted fit of the noise model to one channel: ``counts``
    the (kind, number) of each kind of term (``TERM_KINDS``' names; a kind not named
    has none), the most the structure may use when ``select`` (chosen by its
    score), exactly those terms otherwise. ``filter``: the sensor's
    output-filter power gain G at L ≥ 2 frequencies evenly spaced from 0 Hz
    (G = 1) to fs/2; the white term is seen through it. ``filter_level_std``: the
    relative standard uncertainty of the white level G was measured against (G
    scales as its inverse from its first point that is not 1); the covariance
    carries it."""

def fit_noise_at(
    taus: npt.NDArray[np.float64],
    var: npt.NDArray[np.float64],
    edf: npt.NDArray[np.float64],
    fs: float,
    terms: list[tuple[str, list[float]]],
    filter: npt.NDArray[np.float64] | None = None,
    filter_level_std: float = 0.0,
) -> NoiseFit:
    """The structure of ``terms`` ((kind, parameters) pairs, as ``NoiseFit.terms``)
    fitted to one channel with their correlation times and frequencies held and
    their variances fitted again: no search, no ``ambiguous``. ``filter`` and
    ``filter_level_std`` as :func:`fit_noise`."""

def allan_terms(
    taus: npt.NDArray[np.float64],
    fs: float,
    terms: list[tuple[str, list[float]]],
    filter: npt.NDArray[np.float64] | None = None,
) -> npt.NDArray[np.float64]:
    """Allan variance of each term, given as (kind, parameters) (``TERM_KINDS``),
    at ``taus``: (len(taus), len(terms)); the white term through ``filter``."""

def filter_factor(
    taus: npt.NDArray[np.float64],
    fs: float,
    filter: npt.NDArray[np.float64],
) -> npt.NDArray[np.float64]:
    """c(τ): the white term's Allan variance through the output filter ``filter``
    (power gain from 0 Hz to fs/2, G(0) = 1) over the one without; exact for a gain
    linear between its points at whole cluster sizes τ·fs, read linearly between."""

def density_allan(
    taus: npt.NDArray[np.float64],
    fs: float,
    density: npt.NDArray[np.float64],
) -> npt.NDArray[np.float64]:
    """Allan variance at ``taus`` of a process whose one-sided density (units²/Hz,
    any sign) is ``density`` at L ≥ 2 frequencies evenly spaced from 0 Hz to fs/2,
    linear between them."""

def datasheet(
    terms: list[tuple[str, list[float]]],
    cov: npt.NDArray[np.float64],
    taus: npt.NDArray[np.float64],
    fs: float,
    record: float | None = None,
    filter: npt.NDArray[np.float64] | None = None,
) -> list[tuple[str, tuple[float, float]]]:
    """(name, (value, std)) of N, B, K of a model given as (kind, parameters) terms
    with ``cov`` the covariance of their coordinates; NaN where not resolved.
    ``record``: the record's duration, s (default the longest tau)."""

def model_floor(
    terms: list[tuple[str, list[float]]],
    taus: npt.NDArray[np.float64],
    fs: float,
    filter: npt.NDArray[np.float64] | None = None,
) -> tuple[float, float] | None:
    """(τ, σ) of the floor of the model's deviation over ``taus`` (where B is read),
    or None where the curve has none."""

def datasheet_shares(
    terms: list[tuple[str, list[float]]],
    fs: float,
    record: float,
) -> list[tuple[float, float]]:
    """(white, walk) per term: what it adds to the datasheet's N² and to its K² over a
    record of ``record`` seconds (0 where it counts in neither), the rules of
    ``datasheet``."""
