"""What one term of a noise model gives an extended Kalman filter's model of its
channel: white noise for the measurement, bias states for the filter. Each kind
says its own (``Term.ekf`` in :mod:`imunoise.noise._typed`); the EKF export
(:func:`imunoise.export.ekf_dict`) adds them up over ``model.terms``."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class BiasState:
    """A first-order Gauss–Markov bias state ḃ = −b/τc + w: steady-state standard
    deviation ``sigma`` (rate, in the input's units) and ``correlation_time`` τc (s)."""

    sigma: float
    correlation_time: float

    @property
    def driving_noise_density(self) -> float:
        """√(2σ²/τc), the density of w (rate/√s)."""
        return self.sigma * math.sqrt(2.0 / self.correlation_time)


@dataclass(frozen=True)
class EkfShare:
    """One term's part of an EKF's model of its channel, in the input's units:
    ``white_density`` (rate²·s) is added to the square of the measurement noise's
    density, ``states`` are bias states of their own. The default, nothing: a term
    the filter's model leaves out."""

    white_density: float = 0.0
    states: tuple[BiasState, ...] = ()
