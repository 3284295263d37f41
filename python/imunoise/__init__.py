"""imunoise: noise characterisation of inertial sensors.

Allan deviation and its family with real confidence intervals, noise-model
fitting, log readers for VectorNav VN-100 (ASCII and binary), CSV and ROS bags,
plots and reports. Start with ``imunoise.adev(x, fs)``.
"""

# _support.interrupt is imported first, before the heavy imports: importing it arms
# Ctrl-C for the command line's start-up (exit 130 and one line, not a traceback from
# inside numpy); in any other process it does nothing.
from imunoise._support import interrupt as _interrupt  # noqa: F401

# isort: split
from imunoise import export, units
from imunoise._analysis.align import Aligned, align
from imunoise._analysis.allan_stream import AllanStream
from imunoise._analysis.events import Events, events
from imunoise._analysis.fleet import Fleet, fleet
from imunoise._analysis.hat import ThreeCorneredHat, gcodev, three_cornered_hat
from imunoise._analysis.mount import OwnNoise, own_noise
from imunoise._analysis.thermal import Thermal, thermal
from imunoise._analysis.timefreq import mtie, pdev, tierms
from imunoise._analysis.warmup import Warmup, warmup
from imunoise._core import __version__
from imunoise._simulation.log import simulate_log
from imunoise._simulation.simulate import simulate
from imunoise._support.cpu import apply_environment as _apply_simd_environment
from imunoise.allan import (
    AllanResult,
    adev,
    hdev,
    htotdev,
    mdev,
    mtotdev,
    ohdev,
    tdev,
    theo1,
    theobr,
    theoh,
    totdev,
    ttotdev,
)
from imunoise.datasheet import compare
from imunoise.dynamic import DynamicAllan, dynamic_adev
from imunoise.errors import (
    AssumptionWarning,
    CoverageWarning,
    DataWarning,
    GapWarning,
    ImunoiseDeprecationWarning,
    ImunoiseError,
    ImunoiseTypeError,
    ImunoiseValueError,
    ImunoiseWarning,
    ParseError,
)
from imunoise.noise import NoiseModel, fit
from imunoise.planner import plan
from imunoise.readers import Gaps, ImuLog, ParseIssues
from imunoise.readers.read import read
from imunoise.recording import record
from imunoise.scale import batch
from imunoise.spectrum import Spectrum, psd
from imunoise.stats import describe, distribution
from imunoise.writers.vn import write_vn_ascii, write_vn_binary

_apply_simd_environment()

__all__ = [
    "__version__",
    "Aligned",
    "AllanStream",
    "AssumptionWarning",
    "CoverageWarning",
    "DataWarning",
    "GapWarning",
    "ImunoiseDeprecationWarning",
    "ImunoiseError",
    "ImunoiseTypeError",
    "ImunoiseValueError",
    "ImunoiseWarning",
    "AllanResult",
    "DynamicAllan",
    "Events",
    "Fleet",
    "Thermal",
    "Warmup",
    "Gaps",
    "ImuLog",
    "NoiseModel",
    "OwnNoise",
    "ParseError",
    "ParseIssues",
    "Spectrum",
    "ThreeCorneredHat",
    "adev",
    "align",
    "batch",
    "compare",
    "describe",
    "distribution",
    "dynamic_adev",
    "events",
    "export",
    "fit",
    "fleet",
    "gcodev",
    "hdev",
    "htotdev",
    "mdev",
    "mtie",
    "mtotdev",
    "ohdev",
    "own_noise",
    "pdev",
    "plot",
    "plan",
    "psd",
    "read",
    "record",
    "report",
    "scale",
    "simulate",
    "simulate_log",
    "tdev",
    "theo1",
    "theobr",
    "thermal",
    "three_cornered_hat",
    "theoh",
    "tierms",
    "totdev",
    "ttotdev",
    "units",
    "warmup",
    "write_vn_ascii",
    "write_vn_binary",
]

# Modules that pull in matplotlib (plot, report) or optional dependencies (scale)
# load on first use, so that ``import imunoise`` stays light.
_LAZY_MODULES = ("plot", "report", "scale")


def __getattr__(name: str):
    if name in _LAZY_MODULES:
        import importlib

        return importlib.import_module(f"imunoise.{name}")
    raise AttributeError(f"module 'imunoise' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY_MODULES))
