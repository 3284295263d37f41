"""Noise model of an inertial sensor, fitted to an Allan deviation.

The IEEE Std 952-1997 / 1293-1998 model of the Allan variance of rate data is

.. math::

    \\sigma^2(\\tau) = \\frac{3Q^2}{\\tau^2} + \\frac{N^2}{\\tau}
        + \\frac{2\\ln 2}{\\pi} B^2 + \\frac{K^2\\tau}{3} + \\frac{R^2\\tau^2}{2}

with Q the quantization noise (rate·s), N the angle/velocity random walk
(rate·√s = rate/√Hz, slope −½), B the bias instability (rate, flat part:
σ_flat = √(2 ln2/π)·B ≈ 0.6643·B), K the rate random walk (rate/√s, slope +½)
and R the rate ramp (rate/s, slope +1).

Real sensors are not five terms: their own low-pass filter bends the short
taus and slowly wandering biases put bumps in the curve. The model therefore
also has up to three first-order Gauss–Markov (exponentially correlated) bias
terms, each with a standard deviation σ and a correlation time τc, whose Allan
variance is the discrete AR1 form of IEEE 952 Annex C (slope +½ for τ ≪ τc, a
peak near 1.9 τc, slope −½ for τ ≫ τc), and up to two tones A·sin(2πf₀t + ϕ)
(lines: dither, ripple, a sharp mode, a vehicle's two modes), IEEE 952 Annex C's
sinusoidal term A²·sin⁴(πf₀τ)/(πf₀τ)² in its sampled form 2·(A²/2)·sin⁴(πνm)/(m² sin²πν),
ν = f₀/fs, m = τ·fs, whose frequency is searched like the correlation times,
and at most one resonance: a damped oscillator (second-order Gauss–Markov
process) of standard deviation σ, centre frequency f_r and damping time τr,
autocovariance σ²ρ^|h|·cos(θh) with ρ = exp(−1/(fs·τr)), θ = 2πf_r/fs (a
sensor's filter top or a mechanical mode: a band, not a line), whose Allan
variance is the real part of the AR1 form continued to z = ρe^(iθ).

The sensor's own output filter (a low-pass of any order, a CIC decimator, an FIR)
is no term: given a spectrum (or a log), :func:`fit` measures its gain
G(f) = ``|H(f)|²`` from the spectrum's shape above its white region
(:func:`estimate_filter`) and passes the white noise through it, σ²_N(τ) =
(N²/τ)·c(τ) (:meth:`OutputFilter.factor`), so that no other term draws its roll-off.

:func:`fit` offers two estimators:

``"wls"`` (default)
    Weighted least squares on ln σ̂²(τ) (Rust, faer). Each tau weighs
    ω/(var(ln σ̂²) + δ²): ω is the share of an octave of τ it stands for (so
    octave, 5, 10, 20 or 50 taus per decade carry the same evidence and give the
    same coefficients), var(ln σ̂²) = ψ′(edf/2) its sampling variance, and δ² a
    model-discrepancy variance fitted by maximum likelihood (so a tau with an
    EDF of 10⁶, where the model is only approximately right, cannot outweigh the
    rest). For fixed correlation times every term is linear in its variance:
    non-negative Gauss–Newton steps, a grid and golden-section search over the
    times, and, with ``terms="auto"``, the structure with the lowest BIC.
    Details and the reasons for each choice: ``docs/noise.md``.
``"slopes"``
    The IEEE 952 Annex C / MATLAB example read-off: find the τ where the
    log-log slope of the curve is closest to the term's slope, draw the line
    with the exact slope through that point and read it at the term's τ:
    N at τ = 1 s (slope −½), K at τ = 3 s (slope +½), Q at τ = √3 s (slope −1),
    R at τ = √2 s (slope +1), and B = σ_flat/√(2 ln2/π) at the point of slope 0.

What a user reads, ``model.N``, ``B``, ``K``, ``Q``, ``R``, are the datasheet values of
the whole fitted model (``_datasheet``): a Gauss–Markov term whose hump lies before 1 s counts in
N, a slower one's +½ slope in K, B is the model's flat minimum / 0.6643; every view
prints these. The fit's own parameters are :attr:`NoiseModel.terms`, one typed
term per fitted component (``_typed``: :class:`White`, :class:`GaussMarkov`,
:class:`Tone`, …); :attr:`NoiseModel.components` holds them as parallel arrays.

Whatever the method, :attr:`NoiseModel.readoff` holds the datasheet read-offs
of the data (N at 1 s, K at 3 s, B = σ_min/0.6643) next to the model, and
:attr:`NoiseModel.coverage` says how well the model follows the curve.

Two classic mistakes the code cannot make: B is σ_flat/0.6643 (not 0.664·σ²),
and the +½ slope is rate random walk K (white noise is the −½ slope).

References
----------
IEEE Std 952-1997, "IEEE Standard Specification Format Guide and Test
Procedure for Single-Axis Interferometric Fiber Optic Gyros", Annex C.
N. El-Sheimy, H. Hou, X. Niu, "Analysis and Modeling of Inertial Sensors Using
Allan Variance", IEEE Trans. Instrum. Meas. 57(1), 2008.
MathWorks, "Inertial Sensor Noise Analysis Using Allan Variance" (example).
"""

from __future__ import annotations

from imunoise.noise._ambiguity import Tie
from imunoise.noise._components import Components, Prediction
from imunoise.noise._filter import OutputFilter, estimate_filter
from imunoise.noise._fit import fit
from imunoise.noise._model import NoiseModel, format_table
from imunoise.noise._terms import (
    FLICKER,
    GM_MAX,
    TERMS,
    TONES_MAX,
    gm_white_density,
    model_variance,
    resolution_noise,
    resonance_white_density,
)
from imunoise.noise._typed import (
    Flicker,
    GaussMarkov,
    Motion,
    Quantization,
    Ramp,
    RandomWalk,
    Resonance,
    Term,
    Tone,
    White,
)

__all__ = ["TERMS", "FLICKER", "GM_MAX", "TONES_MAX", "Components", "NoiseModel", "OutputFilter",
           "Prediction", "estimate_filter", "fit",
           "format_table", "gm_white_density", "model_variance", "resolution_noise",
           "resonance_white_density", "Term", "Quantization", "White", "Flicker", "RandomWalk",
           "Ramp", "GaussMarkov", "Tone", "Resonance", "Motion", "Tie"]
