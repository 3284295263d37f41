# rust/bindings/allan.rs: the Allan family.

from typing import final

import numpy as np
import numpy.typing as npt

#: Statistic names the functions below accept, from the Rust table
#: (rust/allan/statistic.rs).
STATISTICS: tuple[str, ...]
#: The statistics that can leave out the terms touching a missing sample (NaN).
GAP_SKIPPING: tuple[str, ...]
#: Fewest samples ThêoBR (and ThêoH) accept: its bias ratio needs 90 phase points.
THEOBR_MIN_SAMPLES: int

@final
class Analysis:
    """The arrays of one analysis; 2-D arrays are (taus, channels)."""

    @property
    def var(self) -> npt.NDArray[np.float64]:
        """Variance at each tau and channel (NaN where gaps leave no term)."""
    @property
    def terms(self) -> npt.NDArray[np.uint64]:
        """Terms each estimate averages (with gaps: the terms used)."""
    @property
    def alpha(self) -> npt.NDArray[np.int32]:
        """Noise type α used for the EDF."""
    @property
    def alpha_identified(self) -> npt.NDArray[np.bool_]:
        """Whether α was identified at that tau (else taken from the nearest ones)."""
    @property
    def edf(self) -> npt.NDArray[np.float64]:
        """Equivalent degrees of freedom."""
    @property
    def missing(self) -> npt.NDArray[np.uint64]:
        """Missing samples (NaN) per channel, shape (channels,)."""

def analyse(
    x: npt.NDArray[np.float64],
    statistic: str,
    ms: npt.NDArray[np.uint64],
    ratio_ladder: str = "taylor-howe",
    ratio_block: int = 1,
) -> Analysis:
    """The analysis of x (n, channels) at averaging factors ms. NaN marks a missing
    sample: adev, oadev, mdev, hdev and ohdev leave out the terms touching one
    (``terms`` counts those used; var and edf are NaN where none is left), the others
    raise ValueError. statistic: one of :data:`STATISTICS`. ThêoBR's bias ratio:
    ``ratio_ladder`` "taylor-howe" (n = ⌊N/30⌋ − 3) or "sp1065" (n = ⌊N/6⌋ − 3);
    ``ratio_block`` b ≥ 1 computes it on every b-th phase point (the fast ThêoBR)."""

def analyse_plan(
    x: npt.NDArray[np.float64],
    statistics: list[str],
    ms: npt.NDArray[np.uint64],
    ratio_ladder: str = "taylor-howe",
    ratio_block: int = 1,
) -> Analysis:
    """As :func:`analyse` with one statistic per tau (``statistics[t]`` at ``ms[t]``,
    ordered by tau); ThêoH is oadev at its short taus, then theobr."""

def theobr_seconds(
    n_phase: int, ms: list[int], ratio_ladder: str = "taylor-howe", ratio_block: int = 1
) -> float:
    """Rough seconds ThêoBR's bias ratio (as ``analyse`` computes it with these
    options) plus Theo1 at ms take on one channel, from the kernel's work model and
    rates measured on the development machine."""

def estimator_terms(
    statistic: str, n_phase: int, ms: npt.NDArray[np.uint64]
) -> npt.NDArray[np.uint64]:
    """Terms each averaging factor's estimate averages (0: the tau does not fit)."""

def estimator_edf(
    statistic: str,
    n_phase: int,
    alphas: npt.NDArray[np.int32],
    ms: npt.NDArray[np.uint64],
) -> npt.NDArray[np.float64]:
    """EDF of a gap-free record of n_phase phase points for noise type alphas[i] at
    averaging factor ms[i], by the statistic's own EDF model (as :func:`analyse`)."""
