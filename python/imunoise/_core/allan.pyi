# rust/bindings/allan.rs: the Allan family.

import numpy as np
import numpy.typing as npt

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
    npt.NDArray[np.uint64],
]:
    """(var, terms, alpha, alpha_identified, edf, missing) for x (n, channels) at
    averaging factors ms; 2-D outputs are (len(ms), channels), ``missing`` (channels,)
    counts each channel's NaN. NaN marks a missing sample: adev, oadev, mdev, hdev and
    ohdev leave out the terms touching one (``terms`` counts those used; var and edf
    are NaN where none is left), the others raise ValueError. statistic: adev, oadev,
    mdev, hdev, ohdev, totdev, mtotdev, htotdev, theo1, theobr."""

def analyse_plan(
    x: npt.NDArray[np.float64],
    statistics: list[str],
    ms: npt.NDArray[np.uint64],
) -> tuple[
    npt.NDArray[np.float64],
    npt.NDArray[np.uint64],
    npt.NDArray[np.int32],
    npt.NDArray[np.bool_],
    npt.NDArray[np.float64],
    npt.NDArray[np.uint64],
]:
    """As :func:`analyse` with one statistic per tau (``statistics[t]`` at ``ms[t]``,
    ordered by tau); ThêoH is oadev at its short taus, then theobr."""

def theobr_work(n_phase: int, ms: list[int]) -> tuple[float, float]:
    """(direct steps, fast units) of ThêoBR's bias ratio plus Theo1 at ms, per channel:
    (N − m)·m/2 per Theo1 below the kernel's direct threshold, N·log2(m)² above."""

def estimator_terms(
    statistic: str, n_phase: int, ms: npt.NDArray[np.uint64]
) -> npt.NDArray[np.uint64]:
    """Terms each averaging factor's estimate averages (0: the tau does not fit)."""
