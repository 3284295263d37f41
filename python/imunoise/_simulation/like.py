"""Noise like a measured sensor's: from its fitted noise model, its Allan deviation
or its power spectral density (``imunoise.simulate(n, fs, like=...)``).

- A :class:`~imunoise.NoiseModel`: each channel simulated from its fitted terms
  (``model.terms``: each term's own process, ``Term.sample``) and passed
  through its measured output filter, the processes :func:`imunoise.fit` models, so
  the simulated record's Allan deviation follows the model.
- An :class:`~imunoise.AllanResult` of rate data: fitted first (:func:`imunoise.fit`),
  then as a model: the route from a measured Allan deviation to its PSD
  (:func:`imunoise.spectrum.model_psd`) and to noise with that PSD.
- A :class:`~imunoise.Spectrum` (or a pair ``(f, psd)`` of one-sided densities):
  Gaussian noise synthesised in the frequency domain, each rFFT bin k of the n
  samples an independent complex normal of variance S(f_k)·fs·n/2 (S interpolated
  log-log between the given frequencies, held at its end values beyond them; the
  0 Hz bin is 0), so the expected periodogram is S. A spectrum holds no phase:
  lines come out as narrow bands of the same power, and no term longer than the
  spectrum's lowest frequency is there.
"""

from __future__ import annotations

import numpy as np

from imunoise._support.validate import integer, sample_rate
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError

__all__ = ["simulate_like", "simulate_terms"]


def simulate_like(source, n_samples: int, fs: float | None, *, channels: int | None,
                  seed) -> np.ndarray:
    """Noise like ``source`` (see the module): shape (n,) for one channel else (n, c)."""
    from imunoise.allan import AllanResult
    from imunoise.noise import NoiseModel
    from imunoise.spectrum import Spectrum

    n = integer(n_samples, "n_samples", 1)
    rng = np.random.default_rng(seed)
    if isinstance(source, AllanResult):
        from imunoise.noise import fit

        if source.kind != "adev":
            raise ImunoiseValueError(f"like= takes an Allan deviation (kind 'adev'); got kind "
                             f"{source.kind!r}")
        source = fit(source, warn_coverage=False)
    if isinstance(source, NoiseModel):
        return _from_model(source, n, _rate(fs, source.fs), channels, rng)
    if isinstance(source, Spectrum):
        f, p = np.asarray(source.f, float), np.asarray(source.psd, float)
        return _from_spectrum(f, p, n, _rate(fs, source.fs), channels, rng)
    if isinstance(source, tuple) and len(source) == 2:
        if fs is None:
            raise ImunoiseValueError("fs must be given with like=(f, psd)")
        f, p = (np.asarray(a, float) for a in source)
        return _from_spectrum(f, p, n, sample_rate(fs), channels, rng)
    raise ImunoiseTypeError("like must be a NoiseModel (imunoise.fit), an AllanResult "
                    "(imunoise.adev), a Spectrum (imunoise.psd) or a pair (f, psd); got "
                    f"{type(source).__name__}")


def _rate(fs, own: float) -> float:
    """The source's own rate: a different ``fs`` would change what its terms mean."""
    if fs is not None and not np.isclose(sample_rate(fs), own, rtol=1e-9):
        raise ImunoiseValueError(f"fs must be the source's own rate ({own} Hz) or None; got {fs}")
    return float(own)


def _channels(channels, available: int) -> list[int]:
    """The source's channels to simulate: all, or the first one repeated ``channels``
    times for a one-channel source."""
    if channels is None:
        return list(range(available))
    c = integer(channels, "channels", 1)
    if available == 1:
        return [0] * c
    if c != available:
        raise ImunoiseValueError(f"channels must be None or {available} (the source's channels); "
                         f"got {c}")
    return list(range(c))


def simulate_terms(terms, n: int, fs: float, rng, *, channels: int = 1,
                   through=None) -> np.ndarray:
    """``channels`` independent records of ``n`` samples at ``fs`` of one channel's
    model: the sum of each term's own process (``Term.sample``), through the output
    filter ``through`` where given. Shape (n,) for one channel else (n, c)."""
    out = np.zeros((n, channels))
    for term in terms:
        out += term.sample(n, fs, rng, channels)
    if through is not None:
        out = through.apply(out)
    return out[:, 0].copy() if channels == 1 else out


def _from_model(model, n: int, fs: float, channels, rng) -> np.ndarray:
    picked = _channels(channels, model.channels)
    columns = [simulate_terms(model.terms[c], n, fs, rng, through=model.filter[c])
               for c in picked]
    out = np.column_stack(columns)
    return out[:, 0] if out.shape[1] == 1 and (channels is None or channels == 1) else out


def _from_spectrum(f, p, n: int, fs: float, channels, rng) -> np.ndarray:
    if f.ndim != 1 or f.size < 2 or p.shape[0] != f.size:
        raise ImunoiseValueError(f"a spectrum needs ≥ 2 frequencies and a psd of as many rows; got "
                         f"f {f.shape}, psd {p.shape}")
    if not (np.all(np.isfinite(f)) and np.all(f > 0) and np.all(np.diff(f) > 0)):
        raise ImunoiseValueError("spectrum frequencies must be finite, > 0 and increasing")
    p = p.reshape(f.size, -1)
    if not (np.all(np.isfinite(p)) and np.all(p >= 0)):
        raise ImunoiseValueError("spectrum densities must be finite and >= 0")
    grid = np.fft.rfftfreq(n, 1.0 / fs)
    log_f = np.log(f)
    columns = []
    for c in _channels(channels, p.shape[1]):
        # log-log interpolation; a zero density stays zero
        level = np.exp(np.interp(np.log(np.maximum(grid, f[0])), log_f,
                                 np.log(np.maximum(p[:, c], 1e-300))))
        if p[:, c].max() == 0:
            level[:] = 0.0
        scale = np.sqrt(level * fs * n / 4.0)  # each of re, im: variance S·fs·n/4
        spectrum = scale * (rng.standard_normal(grid.size) + 1j * rng.standard_normal(grid.size))
        spectrum[0] = 0.0
        if n % 2 == 0:  # the Nyquist bin is real: all its variance in re
            spectrum[-1] = np.sqrt(level[-1] * fs * n / 2.0) * rng.standard_normal()
        columns.append(np.fft.irfft(spectrum, n))
    out = np.column_stack(columns)
    return out[:, 0] if out.shape[1] == 1 and (channels is None or channels == 1) else out
