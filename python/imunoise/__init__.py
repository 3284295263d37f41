"""imunoise: noise characterisation of inertial sensors.

Allan deviation and its family with real confidence intervals, noise-model
fitting, log readers for VectorNav VN-100 (ASCII and binary), CSV and ROS bags,
plots and reports. Start with ``imunoise.adev(x, fs)``.
"""

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
    totdev,
    ttotdev,
)
from imunoise.readers import ImuLog, ParseIssues

__all__ = [
    "__version__",
    "AllanResult",
    "ImuLog",
    "ParseIssues",
    "adev",
    "hdev",
    "htotdev",
    "mdev",
    "mtotdev",
    "tdev",
    "theo1",
    "totdev",
    "ttotdev",
]
