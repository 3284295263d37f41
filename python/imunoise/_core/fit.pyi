# rust/bindings/fit.rs: the noise-model fit.

import numpy as np
import numpy.typing as npt

def fit_noise(
    taus: npt.NDArray[np.float64],
    var: npt.NDArray[np.float64],
    edf: npt.NDArray[np.float64],
    fs: float,
    terms: list[bool],
    gm: int = 3,
    select: bool = True,
) -> tuple[
    npt.NDArray[np.float64],  # (Q², N², B², K², R²)
    npt.NDArray[np.float64],  # (k, 2): (q², τc) per Gauss–Markov term
    npt.NDArray[np.float64],  # (11, 11) covariance of (Q²…R², then q², ln τc per GM term)
    float,  # discrepancy δ
    float,  # chi2 (sampling variance only, octave-weighted)
    float,  # n_eff (octaves of evidence)
    int,  # free parameters
    float,  # BIC
]:
    """Log-space, octave-weighted fit of the noise model (IEEE terms and up to
    ``gm`` Gauss–Markov terms) to one channel; structure chosen by BIC when
    ``select``."""

def noise_terms(
    taus: npt.NDArray[np.float64], fs: float, ieee: list[float], gm: list[tuple[float, float]]
) -> npt.NDArray[np.float64]:
    """Allan variance of each model term at ``taus``: (len(taus), 5 + len(gm))."""
