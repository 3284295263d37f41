"""Simulate rate noise with known IEEE 952 coefficients.

:func:`simulate` returns samples y_k (k = 0..n−1, at rate fs) whose Allan
variance follows

    σ²(τ) = 3Q²/τ² + N²/τ + (2 ln2/π)·B² + K²τ/3 + R²τ²/2

(coefficients in the rate's units: Q rate·s, N rate·√s, B rate, K rate/√s,
R rate/s). Each term is generated independently and summed:

* **N (white rate noise)**: y = N·√fs·w, w ~ N(0, 1) i.i.d. (two-sided PSD N²).
* **K (rate random walk)**: y_k = Σ_{i≤k} (K/√fs)·w_i (increments K√τ0;
  PSD K²/(2πf)²).
* **R (rate ramp)**: y_k = R·k/fs.
* **Q (quantization)**: the derivative of a white phase (angle) term:
  y_k = (x_{k+1} − x_k)·fs with x ~ N(0, Q²) i.i.d., which gives exactly
  3Q²/τ² for the overlapping Allan variance.
* **B (bias instability, flicker rate noise)**: the Kasdin–Walter generator
  (Kasdin & Walter 1992; Kasdin 1995): white noise of standard deviation B
  filtered by h_0 = 1, h_k = h_{k−1}(k − 1 + α/2)/k with α = 1, by FFT
  convolution. Its two-sided PSD is B²τ0/|2 sin(πfτ0)| ≈ B²/(2πf), the IEEE
  952 flicker PSD, whose Allan deviation is flat at √(2 ln2/π)·B ≈ 0.6643·B for
  τ ≫ τ0. For n ≤ 2²² samples the filter spans the whole record (the exact
  Kasdin–Walter process); beyond that the convolution is done by overlap-save
  in blocks with the filter truncated to 2²² taps, so the 1/f law holds down to
  f ≈ fs/2²² (τ up to ≈ 2²¹/fs, e.g. 14 h at 40 Hz) and flattens below it.

Everything is vectorised numpy, chunked so that 10⁸ samples need only the
output array plus a few blocks of scratch.

References
----------
N. J. Kasdin, T. Walter, "Discrete simulation of power law noise", Proc. IEEE
Frequency Control Symposium, 1992, pp. 274–283.
N. J. Kasdin, "Discrete simulation of colored noise and stochastic processes
and 1/f^α power law noise generation", Proc. IEEE 83(5), 1995.
IEEE Std 952-1997, Annex C.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from scipy import fft as _fft

from imunoise._support.deprecation import old_call_forms
from imunoise._support.validate import integer, sample_rate
from imunoise.errors import ImunoiseTypeError, ImunoiseValueError

__all__ = ["simulate", "flicker"]

_CHUNK = 1 << 22
_FLICKER_TAPS = 1 << 22


def _check_coef(name: str, value) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ImunoiseTypeError(f"{name} must be a real number; got {value!r}") from None
    if not (math.isfinite(v) and v >= 0.0):
        raise ImunoiseValueError(f"{name} must be finite and >= 0; got {value!r}")
    return v


def _kw_filter(length: int, alpha: float = 1.0) -> np.ndarray:
    """Kasdin–Walter impulse response h_k, k < length, for PSD ∝ 1/f^alpha."""
    k = np.arange(1, length, dtype=float)
    h = np.empty(length)
    h[0] = 1.0
    h[1:] = np.cumprod((k - 1.0 + alpha / 2.0) / k)
    return h


@old_call_forms(keyword_only=("taps", "out"), renamed={"n": "n_samples"})
def flicker(n_samples: int, scale: float, rng: np.random.Generator, *,
            taps: int = _FLICKER_TAPS, out: np.ndarray | None = None) -> np.ndarray:
    """Kasdin–Walter flicker (1/f) noise: white noise of std ``scale`` filtered.

    Adds into ``out`` when given (shape (n_samples,)), otherwise returns a new array.
    The filter is truncated to ``taps`` taps (see the module docstring).
    """
    n = n_samples
    if out is None:
        out = np.zeros(n)
    if scale == 0.0 or n == 0:
        return out
    L = min(n, taps)
    size = _fft.next_fast_len(2 * L, real=True)
    H = _fft.rfft(_kw_filter(L), size)
    prev = np.zeros(L)  # the L white samples before the current block (zero: start at rest)
    buf = np.zeros(size)
    for s in range(0, n, L):
        m = min(L, n - s)
        cur = rng.standard_normal(m) * scale
        buf[:L] = prev
        buf[L : L + m] = cur
        buf[L + m :] = 0.0
        y = _fft.irfft(_fft.rfft(buf) * H, size)
        out[s : s + m] += y[L : L + m]
        if m == L:
            prev = cur
    return out


@old_call_forms(keyword_only=("channels", "seed"), renamed={"n": "n_samples"})
def simulate(n_samples: int, fs: float, Q: float = 0.0, N: float = 0.0, B: float = 0.0,
             K: float = 0.0, R: float = 0.0, *, channels: int = 1, seed=None,
             gm: Sequence[tuple[float, float]] = (),
             sinusoid: tuple[float, float] | Sequence[tuple[float, float]] | None = None,
             resonance: tuple[float, ...] | None = None,
             motion: tuple[float, float] | None = None, like=None) -> np.ndarray:
    """Rate noise with the given IEEE 952 coefficients, or like a measured sensor's.

    Parameters
    ----------
    n_samples : int
        Number of samples (≥ 1). (The old name ``n=`` still works, deprecated.)
    fs : float
        Sample rate, Hz.
    Q, N, B, K, R : float
        Quantization (rate·s), white/random walk (rate·√s), bias instability
        (rate), rate random walk (rate/√s), rate ramp (rate/s); all ≥ 0.
    channels : int
        Independent channels (same coefficients).
    seed : int, numpy.random.Generator or None
        Seed for :func:`numpy.random.default_rng`.
    gm : sequence of (sigma, tau_c)
        First-order Gauss–Markov bias terms: each a stationary AR1
        x[t] = φ·x[t−1] + w[t] with standard deviation ``sigma`` (rate) and
        correlation time ``tau_c`` (s), φ = exp(−1/(fs·tau_c)) — the process whose
        Allan variance :func:`imunoise.fit` models.
    sinusoid : (amplitude, f0) or sequence of them, optional
        A tone A·sin(2π·f0·t + ϕ) of peak amplitude A (rate) and frequency f0
        (Hz), a random phase ϕ per channel: IEEE 952 Annex C's sinusoidal term,
        Allan variance A²·sin⁴(πf0τ)/(πf0τ)²; several tones add.
    resonance : (sigma, f_r, tau_r) or (sigma, f_r, tau_r, skew), optional
        A damped oscillator (second-order Gauss–Markov process), started
        stationary, with autocovariance sigma²·ρ^|h|·(cos θh + skew·κ·sin θ|h|),
        ρ = exp(−1/(fs·tau_r)), θ = 2π·f_r/fs, κ = sinh(1/(fs·tau_r))/sin θ:
        standard deviation ``sigma`` (rate), frequency ``f_r`` (Hz, at most fs/2),
        damping time ``tau_r`` (s) and ``skew`` in [−1, 1] (default 0; beyond, the
        spectrum would be negative somewhere) — the process of the
        ``"resonance"`` term of :func:`imunoise.fit`. With skew 0 it is the real
        part of the complex AR1 z[t] = ρe^(iθ)·z[t−1] + w[t]; otherwise the
        ARMA(2, 1) process with that autocovariance (a digital Butterworth
        low-pass filter's output has skew 1).
    motion : (sigma, tau_c), optional
        A bounded motion of the mount: the rate (θ[t] − θ[t−1])·fs of an angle
        (velocity, for an accelerometer) θ that is a stationary AR1 of standard
        deviation ``sigma`` (rate·s) and correlation time ``tau_c`` (s) — a
        parked vehicle rocking; the process of the ``"motion"`` term of
        :func:`imunoise.fit`.
    like : NoiseModel, AllanResult, Spectrum or (f, psd), optional
        Noise like a measured sensor's instead of given coefficients: from a fitted
        model's components (each channel its own), from an Allan deviation (fitted
        first), or synthesised from a one-sided PSD (frequencies in Hz, densities in
        units²/Hz; a spectrum holds no phase, so lines come out as narrow bands). The
        coefficients and components above must then be left out; ``fs`` must be the
        source's own rate (or None for a model, result or Spectrum); the channels are
        the source's (``channels`` repeats a one-channel source). See
        ``imunoise._simulation.like``.

    Returns
    -------
    ndarray
        float64, shape (n_samples,) when ``channels == 1`` else
        (n_samples, channels).

    Examples
    --------
    >>> import imunoise
    >>> y = imunoise.simulate(100_000, 100.0, N=1e-3, seed=1)
    >>> y.shape
    (100000,)
    """
    if like is not None:
        given = [name for name, v in (("Q", Q), ("N", N), ("B", B), ("K", K), ("R", R))
                 if v] + [name for name, v in (("gm", gm), ("sinusoid", sinusoid),
                                               ("resonance", resonance), ("motion", motion))
                          if v is not None and len(v)]
        if given:
            raise ImunoiseValueError(
                f"like= replaces the coefficients; leave out {', '.join(given)}")
        from imunoise._simulation.like import simulate_like

        return simulate_like(like, n_samples, fs, channels=None if channels == 1 else channels,
                             seed=seed)
    n = integer(n_samples, "n_samples", 1)
    channels = integer(channels, "channels", 1)
    fs = sample_rate(fs)
    Q, N, B, K, R = (_check_coef(k, v) for k, v in zip("QNBKR", (Q, N, B, K, R), strict=True))
    markov = _check_gm(gm)
    tones = _check_sinusoids(sinusoid)
    oscillator = _check_resonance(resonance, fs)
    moving = _check_motion(motion)
    rng = np.random.default_rng(seed)
    out = np.zeros((n, channels))
    sqfs = math.sqrt(fs)
    for c in range(channels):
        col = out[:, c]
        walk = 0.0
        x_last = None
        for s in range(0, n, _CHUNK):
            m = min(_CHUNK, n - s)
            seg = col[s : s + m]
            if N:
                seg += rng.standard_normal(m) * (N * sqfs)
            if K:
                steps = rng.standard_normal(m) * (K / sqfs)
                steps[0] += walk
                rw = np.cumsum(steps)
                walk = rw[-1]
                seg += rw
            if Q:
                x = rng.standard_normal(m + (1 if x_last is None else 0)) * Q
                if x_last is not None:
                    x = np.concatenate(([x_last], x))
                seg += np.diff(x) * fs
                x_last = x[-1]
            if R:
                seg += (R / fs) * np.arange(s, s + m, dtype=float)
        if B:
            flicker(n, B, rng, out=col)
        for sigma, tau_c in markov:
            col += gauss_markov(n, fs, sigma, tau_c, rng)
        for amplitude, f0 in tones:
            if amplitude > 0:
                phase = rng.uniform(0.0, 2 * math.pi)
                col += amplitude * np.sin(2 * math.pi * f0 / fs * np.arange(n) + phase)
        if oscillator is not None and oscillator[0] > 0:
            col += damped_oscillator(n, fs, *oscillator, rng)
        if moving is not None and moving[0] > 0:
            col += np.diff(gauss_markov(n + 1, fs, *moving, rng)) * fs
    return out[:, 0].copy() if channels == 1 else out


def _check_sinusoids(sinusoid) -> list[tuple[float, float]]:
    """``sinusoid`` — None, one (amplitude, f0) pair or a sequence of them — as a list
    of checked pairs."""
    if sinusoid is None or (isinstance(sinusoid, (list, tuple)) and not sinusoid):
        return []
    try:
        several = len(sinusoid) > 0 and all(np.ndim(p) == 1 for p in sinusoid)
    except TypeError:
        several = False
    pairs = sinusoid if several else [sinusoid]
    return [_size_and_rate(p, "sinusoid", "an", ("amplitude", "f0"), "Hz") for p in pairs]


def _check_motion(motion) -> tuple[float, float] | None:
    return _size_and_rate(motion, "motion", "a", ("sigma", "tau_c"), "s")


def _size_and_rate(value, name: str, article: str, members: tuple[str, str],
                   unit: str) -> tuple[float, float] | None:
    """``value`` as (size ≥ 0, frequency or time > 0 in ``unit``), or None; the
    errors name ``name`` and its two ``members``."""
    if value is None:
        return None
    size_name, rate_name = members
    try:
        size, rate = (float(v) for v in value)
    except (TypeError, ValueError):
        raise ImunoiseTypeError(
            f"{name} must be {article} ({size_name}, {rate_name}) pair or None; "
                        f"got {value!r}") from None
    if not (math.isfinite(size) and size >= 0):
        raise ImunoiseValueError(f"{name} {size_name} must be finite and >= 0; got {size!r}")
    if not (math.isfinite(rate) and rate > 0):
        raise ImunoiseValueError(f"{name} {rate_name} must be finite and > 0 {unit}; got {rate!r}")
    return size, rate


def _check_resonance(resonance, fs: float) -> tuple[float, float, float, float] | None:
    if resonance is None:
        return None
    try:
        values = [float(v) for v in resonance]
        if len(values) not in (3, 4):
            raise ImunoiseValueError
    except (TypeError, ValueError):
        raise ImunoiseTypeError(f"resonance must be a (sigma, f_r, tau_r) triple, a (sigma, f_r, "
                        f"tau_r, skew) quadruple or None; got {resonance!r}") from None
    sigma, f_r, tau_r = values[:3]
    skew = values[3] if len(values) == 4 else 0.0
    if not (math.isfinite(sigma) and sigma >= 0):
        raise ImunoiseValueError(f"resonance sigma must be finite and >= 0; got {sigma!r}")
    if not (math.isfinite(f_r) and 0 < f_r <= fs / 2):
        raise ImunoiseValueError(f"resonance f_r must be in (0, fs/2 = {fs / 2:g}] Hz; got {f_r!r}")
    if not (math.isfinite(tau_r) and tau_r > 0):
        raise ImunoiseValueError(f"resonance tau_r must be finite and > 0 s; got {tau_r!r}")
    if not abs(skew) <= 1:
        raise ImunoiseValueError(f"resonance skew must be in [-1, 1] (a non-negative spectrum); "
                         f"got {skew!r}")
    return sigma, f_r, tau_r, skew


def damped_oscillator(n: int, fs: float, sigma: float, f_r: float, tau_r: float,
                      skew: float, rng: np.random.Generator) -> np.ndarray:
    """Stationary damped oscillator with autocovariance
    sigma²·ρ^|h|·(cos θh + skew·κ·sin θ|h|): for skew 0 (or at fs/2, where the
    quadrature part vanishes) Re z of z[t] = ρe^(iθ)·z[t−1] + w[t]
    (E|z|² = 2 sigma²), else :func:`_arma21`."""
    from scipy.signal import lfilter

    from imunoise.noise._terms import quadrature_bound

    bound = quadrature_bound(f_r, tau_r, fs)
    if skew and math.isfinite(bound):
        return _arma21(n, fs, sigma, f_r, tau_r, skew * bound, rng)
    pole = math.exp(-1.0 / (fs * tau_r)) * complex(math.cos(2 * math.pi * f_r / fs),
                                                   math.sin(2 * math.pi * f_r / fs))
    scale = sigma * math.sqrt(-math.expm1(-2.0 / (fs * tau_r)))  # σ·√(1 − ρ²) per part
    w = (rng.standard_normal(n) + 1j * rng.standard_normal(n)) * scale
    w[0] = (rng.standard_normal() + 1j * rng.standard_normal()) * sigma
    return lfilter([1.0], [1.0, -pole], w).real


def _check_gm(gm) -> list[tuple[float, float]]:
    try:
        pairs = [(float(a), float(b)) for a, b in gm]
    except (TypeError, ValueError):
        raise ImunoiseTypeError(
            f"gm must be a sequence of (sigma, tau_c) pairs; got {gm!r}") from None
    for sigma, tau_c in pairs:
        if not (math.isfinite(sigma) and sigma >= 0):
            raise ImunoiseValueError(f"gm sigma must be finite and >= 0; got {sigma!r}")
        if not (math.isfinite(tau_c) and tau_c > 0):
            raise ImunoiseValueError(f"gm tau_c must be finite and > 0; got {tau_c!r}")
    return pairs


def gauss_markov(n: int, fs: float, sigma: float, tau_c: float,
                 rng: np.random.Generator) -> np.ndarray:
    """Stationary AR1 with standard deviation ``sigma`` and correlation time ``tau_c``."""
    from scipy.signal import lfilter

    phi = math.exp(-1.0 / (fs * tau_c))
    w = rng.standard_normal(n) * (sigma * math.sqrt(-math.expm1(-2.0 / (fs * tau_c))))
    w[0] = rng.standard_normal() * sigma  # start in the stationary distribution
    return lfilter([1.0], [1.0, -phi], w)


def _arma21(n: int, fs: float, sigma: float, f_r: float, tau_r: float, beta: float,
            rng: np.random.Generator) -> np.ndarray:
    """The ARMA(2, 1) process x[t] = a1·x[t−1] + a2·x[t−2] + e[t] + m·e[t−1] whose
    autocovariance is γ(h) = sigma²·ρ^|h|·(cos θh + beta·sin θ|h|).

    γ follows the AR(2) recursion of the poles ρe^(±iθ) (a1 = 2ρ cos θ, a2 = −ρ²)
    from lag 2 on, so w = x − a1·x[−1] − a2·x[−2] is an MA(1) with autocovariances
    c0 = σe²(1 + m²), c1 = σe²·m (Σᵢⱼ φᵢφⱼγ(k + i − j), φ = (1, −a1, −a2)): the
    invertible root |m| ≤ 1 of m² c1 − m c0 + c1 = 0. x = y + m·y[−1] with y the
    AR(2) driven by e, started from its stationary distribution."""
    from scipy.signal import lfilter

    rho = math.exp(-1.0 / (fs * tau_r))
    theta = 2 * math.pi * f_r / fs
    a1, a2 = 2 * rho * math.cos(theta), -rho * rho

    def gamma(h: int) -> float:
        h = abs(h)
        return sigma**2 * rho**h * (math.cos(theta * h) + beta * math.sin(theta * h))

    phi = (1.0, -a1, -a2)
    c0, c1 = (sum(phi[i] * phi[j] * gamma(k + i - j) for i in range(3) for j in range(3))
              for k in (0, 1))
    if abs(c1) <= 1e-15 * abs(c0):
        m, var_e = 0.0, c0
    else:
        disc = math.sqrt(max(c0 * c0 - 4 * c1 * c1, 0.0))
        m = (c0 - disc) / (2 * c1)
        var_e = c1 / m
    # y's stationary (y[−1], y[−2]): variance γy(0), lag-one covariance γy(1).
    g0 = (1 - a2) * var_e / ((1 + a2) * ((1 - a2) ** 2 - a1 * a1))
    g1 = a1 * g0 / (1 - a2)
    start = rng.multivariate_normal([0.0, 0.0], [[g0, g1], [g1, g0]])
    e = rng.standard_normal(n) * math.sqrt(var_e)
    zi = _ar2_state(a1, a2, start)
    y = lfilter([1.0], [1.0, -a1, -a2], e, zi=zi)[0]
    previous = np.concatenate(([start[0]], y[:-1]))
    return y + m * previous


def _ar2_state(a1: float, a2: float, past: np.ndarray) -> np.ndarray:
    """The direct-form-II-transposed state of 1/(1 − a1·B − a2·B²) whose next
    output continues the past outputs ``past`` = (y[−1], y[−2])."""
    y1, y2 = past
    return np.array([a1 * y1 + a2 * y2, a2 * y1])
