# Hand-written stub of the Rust extension `imunoise._core`; keep it in step with
# rust/bindings/. Arrays are numpy arrays; shapes are in the docstrings.

import numpy as np
import numpy.typing as npt

__version__: str

def analyse(
    x: npt.NDArray[np.float64],
    statistic: str,
    ms: npt.NDArray[np.uint64],
) -> tuple[
    npt.NDArray[np.float64],
    npt.NDArray[np.uint64],
    npt.NDArray[np.int32],
    npt.NDArray[np.bool_],
    npt.NDArray[np.float64],
]:
    """(var, terms, alpha, alpha_identified, edf) for x (n, channels) at averaging
    factors ms; 2-D outputs are (len(ms), channels). statistic: adev, oadev, mdev,
    hdev, ohdev, totdev."""

def estimator_terms(
    statistic: str, n_phase: int, ms: npt.NDArray[np.uint64]
) -> npt.NDArray[np.uint64]:
    """Terms each averaging factor's estimate averages (0: the tau does not fit)."""
