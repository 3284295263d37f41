"""An independent numpy evaluation of the output filter's integrals (the core's are in
``rust/fit/filter.rs``): the tests' oracle of ``_core.fit.filter_factor`` and
``_core.fit.density_allan``.

For a function D on ν ∈ [0, ½] cycles per sample, linear between the points
k/(2(L − 1)) and even about 0 and ½, with d_j its Fourier coefficients on the circle
(its samples' DFT times sinc²(πj/M), M = 2(L − 1)), the kernel 2 sin⁴(πνm)/(m² sin²πν)
is a finite cosine sum, and

    S(m) = 2m∫₀^½ D(ν)·2 sin⁴(πνm)/(m² sin²πν) dν = (A − B)/m,
    A = Σ_{|j|<m} (m − |j|) d_j,  B = Σ_{0<j<2m} (m − |j − m|) d_j,

each from numpy's cumulative sums of d_j and j·d_j. c(m) = 1 + S(m) for D = G − 1;
the Allan variance of a one-sided density X is S(m)/(2τ). m = τ·fs is rounded to a
whole sample here (the core reads S linearly between whole sizes).
"""

from __future__ import annotations

import numpy as np


def kernel_sum(taus, fs: float, values) -> np.ndarray:
    """S(m) at ``taus`` for D given by ``values`` on the grid."""
    d = np.asarray(values, dtype=float)
    m = np.maximum(np.rint(np.atleast_1d(np.asarray(taus, dtype=float)) * float(fs)),
                   1).astype(np.int64)
    big = 2 * (d.size - 1)  # samples of D on the whole circle
    circle = np.r_[d, d[-2:0:-1]]
    dft = np.fft.fft(circle).real / big  # even sequence: real coefficients
    j = np.arange(int(2 * m.max()) + 1)
    coef = dft[j % big] * np.sinc(j / big) ** 2  # np.sinc(x) = sin(πx)/(πx)
    p0 = np.cumsum(np.r_[0.0, coef[1:]])  # P0(n) = Σ_{1..n} d_j
    p1 = np.cumsum(np.r_[0.0, j[1:] * coef[1:]])  # P1(n) = Σ_{1..n} j·d_j
    a = m * coef[0] + 2 * (m * p0[m - 1] - p1[m - 1])
    b = p1[m] + 2 * m * (p0[2 * m - 1] - p0[m]) - (p1[2 * m - 1] - p1[m])
    return (a - b) / m


def filter_factor(taus, fs: float, gain) -> np.ndarray:
    """c(τ) of the white term through the power gain ``gain`` (G(0) = 1)."""
    return 1.0 + kernel_sum(taus, fs, np.asarray(gain, dtype=float) - 1.0)


def density_allan(taus, fs: float, density) -> np.ndarray:
    """Allan variance at ``taus`` of a process of one-sided density ``density``."""
    t = np.atleast_1d(np.asarray(taus, dtype=float))
    return kernel_sum(t, fs, density) / (2 * t)
