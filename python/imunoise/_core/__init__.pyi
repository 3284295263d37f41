# Stub of the Rust extension `imunoise._core`: one submodule per file of
# rust/bindings/ (allan, vn, fit, simd, records, digest). Checked against the built module by
# `python -m mypy.stubtest imunoise._core` (tools/check.py lint).

from imunoise._core import allan as allan
from imunoise._core import digest as digest
from imunoise._core import fit as fit
from imunoise._core import records as records
from imunoise._core import simd as simd
from imunoise._core import vn as vn

__version__: str
