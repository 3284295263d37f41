# Hand-written stub of the Rust extension `imunoise._core`; keep it in step with
# rust/bindings/. Arrays are numpy arrays; shapes are in the docstrings.

import os
from collections.abc import Callable
from typing import Any

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

# --- VectorNav parsing and writing (rust/bindings/vn.rs) ------------------------------

def parse_vn(
    source: bytes | str | os.PathLike[str],
    strict: bool = False,
    progress: Callable[[int, int], object] | None = None,
) -> dict[str, Any]:
    """Decode a VN byte stream (bytes, or a path read in chunks) with the GIL released.

    Keys: ``tables`` {message: {column: float64 array}}, ``messages`` {message: count},
    ``issues`` {kind: count}, ``first`` {kind: [(byte_offset, line), ...]},
    ``bytes_total``, ``bytes_parsed``, ``bytes_in_bad_records``, ``bytes_skipped``,
    ``ascii_records``, ``binary_records``, ``missing`` {message: uint64 array of the
    good rows before each damaged record of that type}. ``progress(done, total)``
    after every chunk.
    """

def parse_vn_chunk(data: bytes, strict: bool = False, fin: bool = False) -> dict[str, Any]:
    """Decode the complete records at the start of ``data`` (all of it when ``fin``).

    Same keys as :func:`parse_vn` plus ``bytes_consumed``: the bytes decoded; the rest
    (a record cut by the end of ``data``) starts the next piece. Locations are relative
    to ``data``.
    """

def vn_message_fields() -> dict[str, list[str]]:
    """Field names, in order, of every decoded ASCII message type."""

def vn_binary_fields() -> dict[str, tuple[int, dict[str, int]]]:
    """Group name -> (group index, {field name: field number}) for decodable groups."""

def vn_binary_columns(selection: list[tuple[int, int]]) -> tuple[list[str], str]:
    """(column names in payload order, table name) for a (group, field mask) selection."""

def write_vn_ascii(
    message: str,
    columns: list[npt.NDArray[np.float64]],
    decimals: list[int] | None = None,
    count: npt.NDArray[np.float64] | None = None,
    status: npt.NDArray[np.float64] | None = None,
    crc: bool = False,
    eol: bytes = b"\r\n",
) -> bytes:
    """Sentences of ``message`` from columns in field order (XOR-8 or CRC-16)."""

def write_vn_binary(
    selection: list[tuple[int, int]], columns: dict[str, npt.NDArray[np.float64]]
) -> bytes:
    """Binary packets for ``selection`` from columns named as in vn_binary_columns."""

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
