"""Fleets of logs: one noise analysis per log, in parallel.

:func:`batch` analyses many logs with dask.distributed: one task per log (read,
Allan deviation, noise fit, datasheet comparison), one result row per log, sensor
and axis. A log that fails becomes one row with its error message.
"""

from __future__ import annotations

import glob
import os
import warnings

import numpy as np

from imunoise._support import schema as _schema
from imunoise._support.progress import Progress
from imunoise.allan import adev
from imunoise.datasheet import VERDICTS, compare, load_spec
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError
from imunoise.noise import _typed, fit
from imunoise.readers.log import ISSUE_KINDS
from imunoise.readers.read import read

__all__ = ["BATCH_SENSORS", "BATCH_TAUS", "analyse_log", "analyse_logs", "batch", "expand"]


#: Sensors analysed by :func:`batch`.
BATCH_SENSORS = _schema.ALLAN_SENSORS
_TERM_ORDER = ("N", "B", "K", "Q", "R")
#: Worst verdict first: a row shows its most concerning term (datasheet.VERDICTS order).
_VERDICT_RANK = {w: len(VERDICTS) - i for i, w in enumerate(VERDICTS)}
#: Averaging times of the batch analysis: log-spaced points per decade (as the report).
BATCH_TAUS = _schema.TAUS_PER_DECADE


def expand(paths) -> list[str]:
    """The logs ``paths`` names: paths as given, glob patterns expanded in sorted order;
    ``ValueError`` for a pattern that matches nothing or no path at all."""
    if isinstance(paths, (str, os.PathLike)):
        paths = [paths]
    out: list[str] = []
    for p in paths:
        if not isinstance(p, (str, os.PathLike)):
            raise ImunoiseTypeError(f"paths must be paths or glob patterns; got {type(p).__name__}")
        text = os.fspath(p)
        matches = sorted(glob.glob(text)) if glob.has_magic(text) else [text]
        if not matches:
            raise ImunoiseValueError(f"paths: the pattern {text!r} matches no file")
        out += matches
    if not out:
        raise ImunoiseValueError("paths must name at least one log; got none")
    return out


def _base_row(path: str) -> dict:
    row: dict = {"path": path, "sensor": None, "axis": None, "format": None,
                 "samples": 0, "fs": np.nan, "duration_s": np.nan}
    for kind in ISSUE_KINDS:
        row[f"issues_{kind}"] = 0
    for t in _TERM_ORDER:
        row[t] = np.nan
        row[f"{t}_std"] = np.nan
        row[f"{t}_upper"] = np.nan
        row[f"{t}_supported"] = False
    row["verdict"] = None
    row["error"] = None
    return row


def analyse_log(path: str, spec=None, fs: float | None = None, *,
                components: bool = False) -> list[dict]:
    """The batch rows of one log: one per sensor and axis, or one error row.

    Reads the log (:func:`imunoise.read`), computes the overlapping Allan
    deviation on :data:`BATCH_TAUS` taus per decade, fits the noise model
    (:func:`imunoise.fit`) and compares it with ``spec`` (a name, a TOML file or
    a :class:`~imunoise.datasheet.Spec`; ``None`` skips the comparison). Never
    raises for a bad log: the exception becomes the ``error`` of one row.
    ``components``: each row also holds ``gauss_markov``, the fitted Gauss–Markov
    terms of its axis as ``(sigma, sigma_std, tau_c, tau_c_std)`` tuples by
    increasing τc (rate units and seconds; :func:`imunoise.fleet` lists them).
    """
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            log = read(path, fs=fs)
        if len(log) < 2:
            raise ImunoiseValueError(f"no usable records ({log.issues})")
        sensors = [s for s in BATCH_SENSORS if getattr(log, s) is not None]
        if not sensors:
            raise ImunoiseValueError(f"no gyro or accel channel (has {', '.join(log.channels)})")
        models = {s: fit(adev(getattr(log, s), log.fs, taus=BATCH_TAUS))
                  for s in sensors}
        verdicts: dict[tuple[str, str], dict[str, str]] = {}
        if spec is not None:
            for r in compare(models, spec).rows:
                verdicts.setdefault((r["sensor"], r["axis"]), {})[r["term"]] = r["verdict"]
        rows = []
        for s in sensors:
            m = models[s]
            for j, axis in enumerate(_schema.axis_names(m.channels)):
                row = _base_row(path)
                row.update(sensor=s, axis=axis, format=log.format, samples=len(log),
                           fs=log.fs, duration_s=log.duration)
                for kind, n in log.issues.counts.items():
                    row[f"issues_{kind}"] = int(n)
                for t in _TERM_ORDER:
                    row[t] = float(np.atleast_1d(m.value(t))[j])
                    row[f"{t}_std"] = float(np.atleast_1d(m.std(t))[j])
                    row[f"{t}_upper"] = float(np.atleast_1d(m.upper[t])[j])
                    row[f"{t}_supported"] = bool(np.atleast_1d(m.supported[t])[j])
                v = verdicts.get((s, axis), {})
                if v:
                    row["verdict"] = max(v.values(), key=_VERDICT_RANK.__getitem__)
                for t in _TERM_ORDER:
                    row[f"verdict_{t}"] = v.get(t)
                if components:
                    row["gauss_markov"] = tuple(_typed.pairs(
                        m.terms[j], _typed.GaussMarkov, "sigma", "sigma_std", "tau_c",
                        "tau_c_std"))
                rows.append(row)
        return rows
    except Exception as exc:  # noqa: BLE001 - a bad log is a row, not a failed batch
        row = _base_row(path)
        for t in _TERM_ORDER:
            row[f"verdict_{t}"] = None
        row["error"] = f"{type(exc).__name__}: {exc}"
        return [row]


def _frame(rows: list[dict]):
    import pandas as pd

    df = pd.DataFrame(rows)
    cols = list(_base_row("").keys())
    cols.remove("error")
    cols += [f"verdict_{t}" for t in _TERM_ORDER] + ["error"]
    df = df.reindex(columns=cols)
    df["samples"] = df["samples"].astype("int64")
    for kind in ISSUE_KINDS:
        df[f"issues_{kind}"] = df[f"issues_{kind}"].astype("int64")
    for t in _TERM_ORDER:
        df[f"{t}_supported"] = df[f"{t}_supported"].astype(bool)
    return df


def batch(
    paths,
    client=None,
    spec="vn100",
    *,
    fs: float | None = None,
    progress: bool | None = None,
):
    """Characterise many logs in parallel with dask.distributed.

    Parameters
    ----------
    paths : str, path or sequence of them
        Logs or glob patterns (``"logs/*.bin"``), expanded in sorted order.
    client : None, False, str or distributed.Client
        ``None``: start a local cluster on this machine (2 worker processes, one
        thread each) for this call; a ``Client``: use it unchanged; a string: the
        address of a running scheduler (``"tcp://host:8786"``); ``False``: no Dask,
        analyse the logs one after another in this process (the reference path:
        the results are identical).
    spec : str, path, Spec or None
        Datasheet to compare with (``"vn100"``, a TOML file); ``None`` or
        ``"none"`` skips the verdict.
    fs : float, optional
        Sample rate of logs without timestamps.
    progress : bool, optional
        Show a progress bar on stderr; default: when stderr is a terminal.

    Returns
    -------
    pandas.DataFrame
        One row per log, sensor (gyro, accel) and axis (X, Y, Z), in the order of
        ``paths``: ``path, sensor, axis, format, samples, fs, duration_s``, the
        parse issue counts ``issues_<kind>``, the fitted coefficients ``N, B, K,
        Q, R`` in the log's units (rad/s or m/s² per √s ... as
        :class:`~imunoise.noise.NoiseModel`; NaN where not resolved), their standard
        uncertainties ``<term>_std``, ``<term>_upper`` (the 95 % bound where not
        resolved) and ``<term>_supported``, the datasheet ``verdict`` (worst
        over the specified terms in datasheet.VERDICTS order: fail first, not
        resolved last) and per term
        ``verdict_<term>``, and ``error``. A log that cannot be analysed has one
        row with ``sensor`` empty and the exception in ``error``.

    Notes
    -----
    The workers must be able to import imunoise and to read the paths (on a
    remote cluster: the same files at the same paths).
    """
    results = analyse_logs(paths, client, spec, fs=fs, progress=progress)
    return _frame([row for rows in results for row in rows])


def analyse_logs(paths, client=None, spec="vn100", *, fs: float | None = None,
                 progress: bool | None = None, components: bool = False,
                 desc: str = "imunoise batch") -> list[list[dict]]:
    """:func:`analyse_log` of every log ``paths`` names, in their order: the one loop
    of :func:`batch` and :func:`imunoise.fleet` (``client``, ``spec``, ``fs`` and
    ``progress`` as :func:`batch`; ``components`` as :func:`analyse_log`; ``desc``
    labels the progress bar)."""
    files = expand(paths)
    if isinstance(spec, str) and spec.lower() == "none":
        spec = None
    if spec is not None:
        spec = load_spec(spec)  # fail early, and ship the parsed spec to the workers
    with Progress(progress, len(files), unit="log", desc=desc, leave=True) as bar:
        if client is False:
            results = []
            for p in files:
                results.append(analyse_log(p, spec, fs, components=components))
                bar.step()
            return results
        return _run_dask(files, client, spec, fs, bar, components)


def _run_dask(files, client, spec, fs, bar: Progress, components: bool) -> list[list[dict]]:
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise ImportError(
            "imunoise.batch needs dask.distributed (pip install 'imunoise[scale]'); "
            "pass client=False to run without it"
        ) from None
    own_cluster = own_client = None
    if client is None:
        own_cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                   dashboard_address=None)
        client = own_client = Client(own_cluster)
    elif isinstance(client, str):
        client = own_client = Client(client)
    elif not isinstance(client, Client):
        raise ImunoiseTypeError(
            "client must be None, False, a scheduler address or a distributed.Client; "
            f"got {type(client).__name__}"
        )
    try:
        futures = [client.submit(analyse_log, p, spec, fs, components=components, pure=False)
                   for p in files]
        index = {f.key: i for i, f in enumerate(futures)}
        results: list[list[dict] | None] = [None] * len(files)
        for fut in as_completed(futures):
            i = index[fut.key]
            try:
                results[i] = fut.result()
            except Exception as exc:  # noqa: BLE001 - a lost worker must not lose the batch
                row = _base_row(files[i])
                for t in _TERM_ORDER:
                    row[f"verdict_{t}"] = None
                row["error"] = f"{type(exc).__name__}: {exc}"
                results[i] = [row]
            bar.step()
        return results  # type: ignore[return-value]
    finally:
        if own_client is not None:
            own_client.close()
        if own_cluster is not None:
            own_cluster.close()
