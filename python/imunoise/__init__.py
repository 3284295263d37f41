"""imunoise: noise characterisation of inertial sensors.

Allan deviation and its family with real confidence intervals, noise-model
fitting, log readers for VectorNav VN-100 (ASCII and binary), CSV and ROS bags,
plots and reports. Start with ``imunoise.adev(x, fs)``.
"""

from imunoise import export, units
from imunoise._core import __version__
from imunoise.allan import (
    AllanResult,
    adev,
    hdev,
    htotdev,
    mdev,
    mtotdev,
    tdev,
    theo1,
    theobr,
    theoh,
    totdev,
    ttotdev,
)
from imunoise.datasheet import compare
from imunoise.noise import NoiseModel, fit
from imunoise.readers import Gaps, ImuLog, ParseIssues
from imunoise.readers.read import read
from imunoise.scale import batch
from imunoise.simulate import simulate
from imunoise.simulate_log import simulate_log
from imunoise.stats import describe, distribution
from imunoise.writers.vn import write_vn_ascii, write_vn_binary

__all__ = [
    "__version__",
    "AllanResult",
    "Gaps",
    "ImuLog",
    "NoiseModel",
    "ParseIssues",
    "adev",
    "batch",
    "compare",
    "describe",
    "distribution",
    "export",
    "fit",
    "hdev",
    "htotdev",
    "mdev",
    "mtotdev",
    "read",
    "simulate",
    "simulate_log",
    "tdev",
    "theo1",
    "theobr",
    "theoh",
    "totdev",
    "ttotdev",
    "units",
    "write_vn_ascii",
    "write_vn_binary",
]
