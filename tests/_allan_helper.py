"""Allan deviations for the noise-model tests.

Uses ``imunoise.adev`` when the package provides it; otherwise a stand-in with
the documented ``AllanResult`` fields, built from allantools (overlapping ADEV)
and Greenhall's EDF for white rate noise (alpha = 0).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import imunoise


@dataclass(frozen=True)
class StandInResult:
    kind: str
    overlapping: bool
    taus: np.ndarray
    dev: np.ndarray
    var: np.ndarray
    n: np.ndarray
    edf: np.ndarray
    alpha: np.ndarray
    fs: float
    confidence: float = 0.683


def _octave_taus(n: int, fs: float) -> np.ndarray:
    m = 2 ** np.arange(0, 64)
    m = m[m <= (n - 1) // 2]
    return m / fs


def _standin(x, fs):
    import allantools

    x = np.asarray(x, dtype=float)
    one = x.ndim == 1
    cols = x[:, None] if one else x
    taus = _octave_taus(cols.shape[0], fs)
    devs, edfs, ns = [], [], None
    for c in range(cols.shape[1]):
        t, d, _, nn = allantools.oadev(cols[:, c], rate=fs, data_type="freq", taus=taus)
        devs.append(d)
        ns = np.asarray(nn)
        npts = cols.shape[0] + 1  # phase points
        edfs.append(
            [allantools.edf_greenhall(0, 2, int(round(tt * fs)), npts, overlapping=True)
             for tt in t]
        )
        taus = np.asarray(t)
    dev = np.array(devs).T
    edf = np.array(edfs, dtype=float).T
    if one:
        dev, edf = dev[:, 0], edf[:, 0]
    return StandInResult(kind="adev", overlapping=True, taus=taus, dev=dev, var=dev**2,
                         n=ns, edf=edf, alpha=np.zeros_like(edf, dtype=int), fs=float(fs))


HAVE_ADEV = hasattr(imunoise, "adev")


def allan(x, fs):
    """Overlapping ADEV at octave taus: imunoise.adev or the stand-in."""
    if HAVE_ADEV:
        return imunoise.adev(x, fs, taus="octave", overlapping=True)
    return _standin(x, fs)
