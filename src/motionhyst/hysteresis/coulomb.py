"""Coulomb friction: the rigid limit of the Jenkins element, optionally direction-dependent.

The Jenkins element of eq. (3) with an infinitely stiff spring: a slider
that holds any force between ``-fc_neg`` and ``fc_pos`` while it sticks and
slips at ``fc_pos`` (moving forward) or ``-fc_neg`` (backward), plus an
optional direction-dependent viscous force ``c_pos v`` (``v > 0``) or
``c_neg v`` (``v < 0``): the friction of a positioning axis (e.g. the
EMPS benchmark's ``Fc sign(q') + Fv q'``, with asymmetric ``Fc+, Fc-, Fv+,
Fv-``).  A stage's own damper holds the symmetric viscous part; ``c_pos``
and ``c_neg`` add to it by direction.

In time the element is stepped exactly: the open loop solves each step for
the stick force or the slip force in closed form
(:func:`~motionhyst.hysteresis.stepping.coulomb_implicit`), with no spring
stiffness to resolve and no iteration.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.hysteresis.base import Hysteresis, check_amplitudes, check_positive
from motionhyst.hysteresis.registry import Form, Parameter, register
from motionhyst.hysteresis.stepping import COULOMB, GL_T, GL_W, Stepping, open_loop

__all__ = ["Coulomb"]


def _nonnegative(name: str, value: float) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not (math.isfinite(v) and v >= 0.0):
        raise ValueError(f"{name} must be finite and >= 0, got {value!r}")
    return v


@register
class Coulomb(Hysteresis):
    """Coulomb friction with exact sticking, the rigid limit of eq. (3).

    ``w = fc_pos + c_pos v`` for ``v > 0``, ``w = -fc_neg + c_neg v`` for
    ``v < 0``, any ``-fc_neg <= w <= fc_pos`` at rest (the force that keeps it
    at rest).  The symmetric element is ``Coulomb(fc=...)``; the
    direction-dependent one ``Coulomb(fc_pos=..., fc_neg=..., c_pos=...,
    c_neg=...)`` (the scenario's ``[hysteresis]`` in its ``asymmetric``
    form).

    Parameters
    ----------
    fc : float, optional
        Slip force in both directions [N], > 0 (or give `fc_pos` and `fc_neg`).
    fc_pos, fc_neg : float, optional
        Slip forces moving forward and backward [N], > 0.
    c_pos, c_neg : float
        Viscous friction moving forward and backward [N s/m], >= 0 (default 0).

    Examples
    --------
    >>> from motionhyst.hysteresis import Coulomb
    >>> el = Coulomb(fc=20.0)
    >>> el.response([0.0, 1e-3, 1e-3, 0.0]).tolist()     # slips, sticks (holds), slips back
    [0.0, 20.0, 20.0, -20.0]
    >>> D = el.describing_function(0.01)                  # (4/pi) fc / A, pure dissipation
    >>> round(D.imag, 2), D.real
    (2546.48, 0.0)
    >>> Coulomb(fc_pos=20.1, fc_neg=20.6, c_pos=166.7, c_neg=240.4).to_dict()["fc_neg"]
    20.6
    """

    name = "coulomb"
    rate_independent = False
    #: No elastic range: a time step changes from stick to slip at a parameter's whim, so
    #: identification differentiates its simulation by secants, not sensitivities
    rigid = True
    parameters = (Parameter("fc", "N", "slip (Coulomb) force f_c, both directions"),)
    forms = (Form("asymmetric", "asymmetric", (
        Parameter("fc_pos", "N", "slip force moving forward"),
        Parameter("fc_neg", "N", "slip force moving backward"),
        Parameter("c_pos", "N s/m", "viscous friction moving forward", 0.0, "nonnegative"),
        Parameter("c_neg", "N s/m", "viscous friction moving backward", 0.0, "nonnegative"))),)

    def __init__(self, fc: float | None = None, *, fc_pos: float | None = None,
                 fc_neg: float | None = None, c_pos: float = 0.0, c_neg: float = 0.0) -> None:
        super().__init__()
        if fc is not None:
            if fc_pos is not None or fc_neg is not None:
                raise ValueError("give fc, or fc_pos and fc_neg, not both")
            fc_pos = fc_neg = fc
        if fc_pos is None or fc_neg is None:
            raise ValueError("the Coulomb model needs fc, or fc_pos and fc_neg")
        self.fc_pos = check_positive("fc_pos", fc_pos)
        self.fc_neg = check_positive("fc_neg", fc_neg)
        self.c_pos = _nonnegative("c_pos", c_pos)
        self.c_neg = _nonnegative("c_neg", c_neg)
        self.reset()

    @classmethod
    def asymmetric(cls, fc_pos: float, fc_neg: float, c_pos: float = 0.0,
                   c_neg: float = 0.0) -> Coulomb:
        """The direction-dependent element (the scenario's ``asymmetric`` form).

        Parameters
        ----------
        fc_pos, fc_neg : float
            Slip forces forward and backward [N].
        c_pos, c_neg : float
            Viscous friction forward and backward [N s/m].

        Returns
        -------
        Coulomb
        """
        return cls(fc_pos=fc_pos, fc_neg=fc_neg, c_pos=c_pos, c_neg=c_neg)

    @property
    def viscous_damping(self) -> float:
        """The mean of ``c_pos`` and ``c_neg`` [N s/m]: the part of the viscous force by
        direction that is linear in the velocity.

        Examples
        --------
        >>> Coulomb(fc_pos=20.1, fc_neg=20.6, c_pos=166.7, c_neg=240.4).viscous_damping
        203.55
        """
        return 0.5 * float(self.c_pos + self.c_neg)

    @property
    def symmetric(self) -> bool:
        """True for equal slip forces and no viscous terms (``fc`` alone)."""
        return self.fc_pos == self.fc_neg and self.c_pos == 0.0 and self.c_neg == 0.0

    @property
    def fc(self) -> float:
        """Mean slip force ``(fc_pos + fc_neg) / 2`` [N]."""
        return 0.5 * (self.fc_pos + self.fc_neg)

    def __repr__(self) -> str:
        if self.symmetric:
            return f"Coulomb(fc={self.fc_pos!r})"
        return (f"Coulomb(fc_pos={self.fc_pos!r}, fc_neg={self.fc_neg!r}, "
                f"c_pos={self.c_pos!r}, c_neg={self.c_neg!r})")

    @property
    def initial_stiffness(self) -> float:
        """0: the element has no elastic range (rigid while it sticks, a force while it slips);
        the linear approximations of a stage see no spring from it."""
        return 0.0

    def describing_function(self, A: ArrayLike, omega: ArrayLike | None = None):
        """``D = j (2 (fc_pos + fc_neg) / (pi A) + omega (c_pos + c_neg) / 2)`` [N/m].

        The slip force's first harmonic (eq. 11, the Jenkins element's small-zeta
        limit) and the viscous terms' mean; an unequal `fc_pos`, `fc_neg` adds a
        constant force, not in ``D``.  `omega` [rad/s] is needed only with viscous terms.

        Parameters
        ----------
        A : array_like
            Amplitude(s) [m], >= 0.
        omega : array_like, optional
            Angular frequency [rad/s], broadcast against `A`; required with viscous terms.
        """
        a = check_amplitudes(A)
        c = 0.5 * (self.c_pos + self.c_neg)
        if omega is None:
            if c > 0.0:
                raise ValueError("the Coulomb model with viscous terms is rate-dependent: "
                                 "describing_function needs omega")
            omega = 0.0
        om = np.asarray(omega, dtype=float)
        with np.errstate(divide="ignore"):
            d = 1j * (2.0 * (self.fc_pos + self.fc_neg) / (np.pi * a) + om * c)
        return complex(d) if np.ndim(d) == 0 else d

    def response(self, x: ArrayLike, w0: float = 0.0, t: ArrayLike | None = None
                 ) -> NDArray[np.float64]:
        """Force for displacement samples `x` (at times `t`, needed for viscous terms).

        Moving between samples, the slip force (and the viscous force of the
        interval's mean velocity); not moving, the force held, starting at `w0`.

        Parameters
        ----------
        x : array_like
            Displacement samples [m].
        w0 : float
            Force held at the first sample [N], ``-fc_neg <= w0 <= fc_pos``.
        t : array_like, optional
            Sample times [s] (uniform), required if `c_pos` or `c_neg` is not 0.

        Returns
        -------
        ndarray
            Force at each sample [N].
        """
        xs = np.ascontiguousarray(x, dtype=float)
        if xs.ndim != 1 or not np.all(np.isfinite(xs)):
            raise ValueError("x must be one-dimensional and finite")
        if not -self.fc_neg <= w0 <= self.fc_pos:
            raise ValueError(f"w0 must be within -fc_neg .. fc_pos, got {w0}")
        h = 0.0
        if self.c_pos > 0.0 or self.c_neg > 0.0:
            if t is None:
                raise ValueError("the Coulomb model with viscous terms needs the sample times t")
            ts = np.asarray(t, dtype=float)
            if ts.shape != xs.shape or xs.size < 2 or np.any(np.diff(ts) <= 0):
                raise ValueError("t must increase and match x")
            h = float(np.mean(np.diff(ts)))
        st = self.time_stepping()
        return open_loop(st.codes, st.params, np.array([float(w0)]), xs, h, GL_T, GL_W)

    def __call__(self, x: float) -> float:
        """Advance by one displacement sample (the rate-independent part; see :meth:`response`)."""
        if self.c_pos > 0.0 or self.c_neg > 0.0:
            raise TypeError("the Coulomb model with viscous terms is rate-dependent; use "
                            "response(x, t=...)")
        return super().__call__(x)

    def periodic_harmonics(self, X: NDArray[np.complex128], n_harmonics: int,
                           omega: float | None = None) -> NDArray[np.complex128]:
        """Harmonics of the periodic output (the period sampled finely, its last run).

        Parameters
        ----------
        X : ndarray of complex
            Harmonics ``X_0 .. X_M`` of the displacement over one period (``rfft / N`` scaling).
        n_harmonics : int
            Highest output harmonic ``H``.
        omega : float, optional
            Angular frequency of the period [rad/s]; required with viscous terms.
        """
        from motionhyst.hysteresis.periodic import sample_period

        H = int(n_harmonics)
        N = max(8 * H, 8 * (len(X) - 1), 8192)
        x = sample_period(X, N)
        xs = np.concatenate([x, x, x[:1]])
        om = 0.0 if omega is None else float(omega)
        if (self.c_pos > 0.0 or self.c_neg > 0.0) and om <= 0.0:
            raise ValueError("the Coulomb model with viscous terms needs omega")
        t = np.arange(xs.size) * (2 * np.pi / (om * N)) if om > 0.0 else None
        w = self.response(xs, t=t)[N: 2 * N]
        return (np.fft.rfft(w) / N)[: H + 1]

    def time_stepping(self) -> Stepping:
        """The rigid slider as the compiled time step advances it (:mod:`.stepping`)."""
        return Stepping.from_rows([(COULOMB, (self.fc_pos, self.fc_neg, self.c_pos,
                                              self.c_neg))], max(self.fc_pos, self.fc_neg))

    def to_dict(self) -> dict:
        """Parameters as a JSON-ready dictionary (``fc`` alone when symmetric)."""
        if self.symmetric:
            return {"model": self.name, "fc": self.fc_pos}
        return {"model": self.name, "fc_pos": self.fc_pos, "fc_neg": self.fc_neg,
                "c_pos": self.c_pos, "c_neg": self.c_neg}
