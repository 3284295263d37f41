"""Warnings that point at the caller's line, not at imunoise's.

A warning raised deep in the library (a reader four calls below ``imunoise.read``, the
gap check below ``adev``) is about the call the user wrote: :func:`warn` walks the stack
past every frame inside the imunoise package and gives :func:`warnings.warn` the
stacklevel of the first frame outside it, so ``warning.filename`` and ``lineno`` name
the user's script or test. (Python 3.12's ``skip_file_prefixes`` does the same; the
package supports 3.11.)
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

from imunoise.errors import CoverageWarning, ImunoiseDeprecationWarning, ImunoiseWarning

__all__ = ["warn"]

#: Files under this folder are imunoise's own.
_PACKAGE = str(Path(__file__).resolve().parents[1])


def _inside(filename: str) -> bool:
    try:
        return str(Path(filename).resolve()).startswith(_PACKAGE)
    except (OSError, ValueError):  # "<string>", "<frozen ...>"
        return False


#: The built-in categories a call site may still name, as imunoise's own.
_OWN = {UserWarning: ImunoiseWarning, RuntimeWarning: CoverageWarning,
        DeprecationWarning: ImunoiseDeprecationWarning}


def warn(message, category: type[Warning] = ImunoiseWarning) -> None:
    """:func:`warnings.warn` at the first frame outside the imunoise package, always as
    an :class:`~imunoise.errors.ImunoiseWarning` (a built-in ``category`` becomes its
    imunoise kind), so that one filter silences every imunoise warning."""
    if not issubclass(category, ImunoiseWarning):
        category = _OWN.get(category, ImunoiseWarning)
    frame = sys._getframe(1)
    level = 2  # stacklevel 2 is this function's caller
    while frame is not None and _inside(frame.f_code.co_filename):
        frame = frame.f_back
        level += 1
    warnings.warn(message, category, stacklevel=max(level - 1, 1) if frame is None else level)
