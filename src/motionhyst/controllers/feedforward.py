"""Feedforward from the setpoint: acceleration, jerk, snap, viscous, Coulomb terms, advanced.

The force a motion controller adds to its feedback, computed from the setpoint
``r`` alone::

    u_ff = m r'' + cj r''' + cs r'''' + c r' + fc sign(r')   (+ phi_hat(r), a hysteresis model)

with ``m`` the rigid-body mass (the paper's ``C_ff = P_r^-1 = M s^2`` when
only ``m`` is given; ``cj``, ``cs``: the stage's jerk and snap terms,
:mod:`motionhyst.controllers.inverse`).  A sampled controller applies its whole output
``d`` samples late; a machine reads the setpoint that many samples ahead for
the feedforward (``advance_samples = a``: ``u_ff,k`` from ``r(t_k + a T)``),
which takes the delay out of the feedforward path: the rigid-body
feedforward, sampled at 10 kHz and delayed by 1.5 samples with the feedback,
leaves the Table I loop an error far above the one the dynamic link causes
unless it is advanced by the delay and half a sample of hold, ``a = d + 1/2``.

Examples
--------
>>> import numpy as np
>>> from motionhyst.controllers.feedforward import Feedforward
>>> ff = Feedforward(mass=22.5, viscous=2.0, coulomb=0.5)
>>> float(ff.force(velocity=0.1, acceleration=-1.0))      # -22.5 + 0.2 + 0.5
-21.8
>>> complex(ff.linear_response(1.0))                       # -m w^2 + j c w
(-22.5+2j)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["STANDSTILL", "Feedforward"]

#: A setpoint velocity at most this [m/s] is a standstill for the Coulomb term (sign 0): a
#: sample that falls on a reversal gives no force, whatever the velocity's round-off.
STANDSTILL = 1e-12


@dataclass(frozen=True)
class Feedforward:
    """The setpoint feedforward ``m r'' + cj r''' + cs r'''' + c r' + fc sign(r')``, read ahead.

    Parameters
    ----------
    mass : float, optional
        ``m`` [kg], >= 0; None takes the plant's rigid-body mass ``M`` (the paper's
        ``M s^2``, :meth:`with_mass`).
    viscous : float
        ``c`` [N s/m], >= 0.
    coulomb : float
        ``fc`` [N], >= 0.
    advance_samples : float
        ``a >= 0``: the feedforward of a sampled controller reads the setpoint
        ``a`` samples ahead (fractional allowed); needs a sampled controller.
    jerk, snap : float
        ``cj`` [N s^3/m] and ``cs`` [N s^4/m], finite (0: none): the stage's damping
        and compliance terms (:func:`~motionhyst.controllers.inverse.stage_inverse`).

    Examples
    --------
    >>> from motionhyst.controllers.feedforward import Feedforward
    >>> Feedforward().with_mass(22.5).mass
    22.5
    """

    mass: float | None = None
    viscous: float = 0.0
    coulomb: float = 0.0
    advance_samples: float = 0.0
    jerk: float = 0.0
    snap: float = 0.0

    def __post_init__(self) -> None:
        for name in ("jerk", "snap"):
            if not math.isfinite(getattr(self, name)):
                raise ValueError(f"feedforward {name} must be finite, got {getattr(self, name)!r}")
        for name in ("viscous", "coulomb", "advance_samples", "mass"):
            v = getattr(self, name)
            if v is None:
                continue
            if not (math.isfinite(v) and v >= 0):
                raise ValueError(f"feedforward {name} must be finite and >= 0, got {v!r}")

    def with_mass(self, mass: float) -> Feedforward:
        """This feedforward with ``m`` given (when it takes the plant's mass).

        Parameters
        ----------
        mass : float
            The plant's rigid-body mass [kg], used when :attr:`mass` is None.
        """
        return self if self.mass is not None else replace(self, mass=float(mass))

    @property
    def is_linear(self) -> bool:
        """True without a Coulomb term."""
        return self.coulomb == 0.0

    def force(self, velocity: ArrayLike, acceleration: ArrayLike, jerk: ArrayLike = 0.0,
              snap: ArrayLike = 0.0) -> NDArray[np.float64]:
        """``m r'' + cj r''' + cs r'''' + c r' + fc sign(r')`` [N] from the setpoint's derivatives.

        Parameters
        ----------
        velocity, acceleration : array_like
            ``r'`` [m/s] and ``r''`` [m/s^2] (already read ahead, if advanced).
        jerk, snap : array_like
            ``r'''`` [m/s^3] and ``r''''`` [m/s^4] (needed with those terms only).
        """
        v = np.asarray(velocity, dtype=float)
        m = 0.0 if self.mass is None else self.mass
        out = m * np.asarray(acceleration, dtype=float) + self.viscous * v + self.coulomb_force(v)
        if self.jerk:
            out = out + self.jerk * np.asarray(jerk, dtype=float)
        if self.snap:
            out = out + self.snap * np.asarray(snap, dtype=float)
        return out

    def coulomb_force(self, velocity: ArrayLike) -> NDArray[np.float64]:
        """``fc sign(r')`` [N], 0 at a standstill (``|r'| <=`` :data:`STANDSTILL`).

        Parameters
        ----------
        velocity : array_like
            ``r'`` [m/s].
        """
        v = np.asarray(velocity, dtype=float)
        return self.coulomb * np.where(np.abs(v) <= STANDSTILL, 0.0, np.sign(v))

    def linear_response(self, omega: ArrayLike) -> NDArray[np.complex128]:
        """``cs (j w)^4 + cj (j w)^3 + m (j w)^2 + c j w``: the linear terms' force per unit
        setpoint at `omega` [rad/s].

        Parameters
        ----------
        omega : array_like
            Angular frequencies [rad/s].
        """
        s = 1j * np.asarray(omega, dtype=float)
        m = 0.0 if self.mass is None else self.mass
        return ((self.snap * s + self.jerk) * s + m) * s * s + self.viscous * s

    def coulomb_fundamental(self, amplitude: float) -> complex:
        """Fundamental of ``fc sign(r')`` per unit setpoint, ``r = A sin(w t)``: ``4j fc / (pi A)``.

        Parameters
        ----------
        amplitude : float
            ``A`` [m], > 0.
        """
        return 4j * self.coulomb / (math.pi * float(amplitude))

    def to_dict(self) -> dict:
        """JSON-ready dictionary (the ``[feedforward]`` keys)."""
        out: dict = {}
        if self.mass is not None:
            out["acceleration"] = self.mass
        for key in ("viscous", "coulomb", "advance_samples", "jerk", "snap"):
            if getattr(self, key):
                out[key] = getattr(self, key)
        return out
