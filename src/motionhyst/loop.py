"""The motion control loop of the paper's Fig. 3 and its linear closed-loop transfers.

The loop is ``u = C e + u_ff``, ``e = r - y2``, ``y1 = P1 (u - w)``,
``y2 = P2 (u - w)`` with the hysteresis force ``w = phi(y1)`` and the
rigid-body feedforward ``u_ff = M r''`` (``C_ff = P_r^-1 = M s^2``).
Solving the linear part for the two inputs ``r`` and ``w`` gives::

    e  = (1 - P2 C_ff) / (1 + C P2) r  +  P2 / (1 + C P2) w
    y1 = P1 (C + C_ff) / (1 + C P2) r  -  P1 / (1 + C P2) w

Only the second terms involve the hysteresis, and they are of the size of the
tracking error, so every analysis computes them directly rather than by
subtracting positions.  For LTI systems the transfers are formed as
polynomial ratios with common factors ``s^n`` cancelled, so ``s = 0`` (DC) is
exact: a controller without integrator gives ``P2 / (1 + C P2) -> 1 / C(0)``.
"""

from __future__ import annotations

import control
import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.hysteresis.base import Hysteresis
from motionhyst.lti import PolyTF, cancel_s, polysub_exact, tf_poly, trim
from motionhyst.systems import MeasuredPlant, TwoMassStage, bandwidth, freqresp

TRANSFERS = ("r->e", "r->y1", "w->e", "w->y1")


class Loop:
    """Plant, controller, hysteresis and feedforward of the paper's Fig. 3.

    Parameters
    ----------
    plant : TwoMassStage or ModalPlant or MeasuredPlant or tuple
        The stage: a :class:`~motionhyst.systems.TwoMassStage`, a plant fitted
        to a measured FRF (:class:`~motionhyst.frf_fit.ModalPlant`), the raw
        measured plant, or a tuple ``(P1, P2)`` of python-control LTI systems
        (then `mass` is required for the feedforward).  Any object with
        attributes ``P1``, ``P2`` and ``M`` is taken as a plant.
    controller : python-control LTI system
        Feedback controller ``C``.
    hysteresis : Hysteresis, optional
        The dynamic link ``phi`` acting at ``y1``; None for none.
    feedforward : {"rigid-body", None}
        ``C_ff = M s^2`` (the paper's feedforward) or no feedforward.
    mass : float, optional
        Rigid-body mass ``M`` for the feedforward [kg]; defaults to the plant's.
    hysteresis_feedforward : Hysteresis, optional
        A model ``phi_hat`` driven by the reference and added to the
        feedforward force: ``u_ff = M r'' + phi_hat(r)``.

    Examples
    --------
    The paper's Table I loop, its closed-loop transfers and bandwidth:

    >>> import numpy as np
    >>> from motionhyst import Jenkins, LeadLagLowpass, Loop, TwoMassStage
    >>> stage = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)
    >>> C = LeadLagLowpass(K=6.2e6, f1=60.0, f2=240.0, flp=700.0, beta=0.6)
    >>> loop = Loop(stage, C, Jenkins(k=20.0, fc=0.05))    # rigid-body feedforward M s^2
    >>> loop.M
    22.5
    >>> print(f"{loop.bandwidth_hz():.1f} Hz")
    120.6 Hz
    >>> bool(np.all(loop.closed_loop_poles().real < 0))
    True
    >>> e_over_r = loop.transfer("r->e", 2 * np.pi * np.array([5.0, 10.0]))
    >>> print(np.abs(e_over_r))                            # the linear loop's tracking error
    [1.858e-07 2.976e-06]
    """

    def __init__(self, plant, controller, hysteresis: Hysteresis | None = None,
                 feedforward: str | None = "rigid-body", mass: float | None = None,
                 hysteresis_feedforward: Hysteresis | None = None) -> None:
        if isinstance(plant, TwoMassStage | MeasuredPlant) or all(
                hasattr(plant, a) for a in ("P1", "P2", "M")):
            P1, P2 = plant.P1, plant.P2
            mass = plant.M if mass is None else mass
        else:
            try:
                P1, P2 = plant
            except Exception:
                raise TypeError("plant must be a TwoMassStage, a ModalPlant, a MeasuredPlant "
                                "or a tuple (P1, P2)") from None
        if feedforward not in ("rigid-body", None):
            raise ValueError(f"unknown feedforward {feedforward!r}; use 'rigid-body' or None")
        if feedforward == "rigid-body" and (mass is None or not mass > 0):
            raise ValueError("rigid-body feedforward needs the mass M > 0")
        self.plant = plant
        self.P1, self.P2 = P1, P2
        self.controller = controller
        self.hysteresis = hysteresis
        self.feedforward = feedforward
        self.M = float(mass) if mass is not None else None
        self.hysteresis_feedforward = hysteresis_feedforward
        self.is_lti = not any(isinstance(s, control.FrequencyResponseData)
                              for s in (P1, P2, controller))
        self._poly = self._closed_loop_polys() if self.is_lti else None
        self._poles: NDArray[np.complex128] | None = None

    @property
    def Pr(self) -> control.TransferFunction:
        """Rigid-body model ``1 / (M s^2)``."""
        if self.M is None:
            raise ValueError("the loop has no rigid-body mass")
        return control.tf([1.0], [self.M, 0.0, 0.0])

    def _closed_loop_polys(self) -> dict[str, PolyTF]:
        n1, d1 = tf_poly(self.P1)
        n2, d2 = tf_poly(self.P2)
        nc, dc = tf_poly(self.controller)
        char = np.polyadd(np.polymul(d2, dc), np.polymul(n2, nc))  # (1 + C P2) d2 dc
        if self.feedforward == "rigid-body":
            # 1 - P2 M s^2 = (d2 - M s^2 n2) / d2; C + C_ff = (nc + M s^2 dc) / dc
            ff_num = polysub_exact(d2, np.polymul(n2, [self.M, 0.0, 0.0]))
            cff = np.polyadd(nc, np.polymul(dc, [self.M, 0.0, 0.0]))
        else:
            ff_num, cff = d2, nc
        out = {
            "r->e": cancel_s(np.polymul(ff_num, dc), char),
            "r->y1": cancel_s(np.polymul(np.polymul(n1, d2), cff), np.polymul(d1, char)),
            "w->e": cancel_s(np.polymul(n2, dc), char),
            "w->y1": cancel_s(-np.polymul(np.polymul(n1, d2), dc), np.polymul(d1, char)),
        }
        return {k: PolyTF(*v) for k, v in out.items()}

    def transfer(self, name: str, omega: ArrayLike) -> NDArray[np.complex128]:
        """Frequency response of a closed-loop transfer at `omega` [rad/s].

        Parameters
        ----------
        name : {"r->e", "r->y1", "w->e", "w->y1"}
            From reference or hysteresis force to tracking error or ``y1``.
        omega : array_like
            Angular frequencies [rad/s]; 0 is allowed for LTI loops.
        """
        if name not in TRANSFERS:
            raise ValueError(f"unknown transfer {name!r}; one of {', '.join(TRANSFERS)}")
        w = np.asarray(omega, dtype=float)
        if self._poly is not None:
            return self._poly[name](w)
        P1, P2 = freqresp(self.P1, w), freqresp(self.P2, w)
        C = freqresp(self.controller, w)
        Cff = self.M * (1j * w) ** 2 if self.feedforward == "rigid-body" else 0.0
        sens = 1.0 / (1.0 + C * P2)
        return {"r->e": (1.0 - P2 * Cff) * sens, "r->y1": P1 * (C + Cff) * sens,
                "w->e": P2 * sens, "w->y1": -P1 * sens}[name]

    def transfer_tf(self, name: str) -> control.TransferFunction:
        """A closed-loop transfer as a python-control transfer function (LTI loops only)."""
        if self._poly is None:
            raise ValueError("closed-loop transfer functions need LTI plant and controller")
        if name not in TRANSFERS:
            raise ValueError(f"unknown transfer {name!r}; one of {', '.join(TRANSFERS)}")
        return self._poly[name].tf()

    def closed_loop_poles(self) -> NDArray[np.complex128]:
        """Poles of ``1 + C P2`` (LTI loops only; ValueError for measured data)."""
        if self._poly is None:
            raise ValueError("closed-loop poles, the time simulation and the steady state need "
                             "LTI plant and controller; a raw measured plant has none: fit it "
                             '([plant] use = "fit")')
        if self._poles is None:
            self._poles = np.roots(self._poly["w->e"].den)
        return self._poles.copy()

    def check_stable(self) -> None:
        """Raise ``ValueError`` unless the linear loop is stable.

        Checked without the dynamic link and with it stuck (a spring of the
        hysteresis's initial stiffness at ``y1``), the two linear extremes of
        the element.  Only LTI loops can be checked.
        """
        if self._poly is None:
            return
        cases = [("", self._poly["w->e"].den)]
        if self.hysteresis is not None:
            # stuck link, w = kJ y1: characteristic polynomial of 1 + kJ P1 + C P2, over a
            # common denominator of P1 and P2 (shared by both for a two-mass stage)
            n1, d1 = tf_poly(self.P1)
            n2, d2 = tf_poly(self.P2)
            nc, dc = tf_poly(self.controller)
            kj = self.hysteresis.initial_stiffness
            if d1.shape == d2.shape and np.array_equal(d1, d2):
                n1c, n2c, d = n1, n2, d1
            else:
                n1c, n2c, d = np.polymul(n1, d2), np.polymul(n2, d1), np.polymul(d1, d2)
            stuck = np.polyadd(np.polymul(np.polyadd(d, kj * n1c), dc), np.polymul(n2c, nc))
            cases.append((" with the dynamic link stuck", stuck))
        for what, den in cases:
            p = np.roots(trim(den))
            if p.size and np.max(p.real) >= 0:
                worst = p[np.argmax(p.real)]
                raise ValueError(f"the controller does not stabilise the loop{what} "
                                 f"(closed-loop pole at {worst.real:.4g}{worst.imag:+.4g}j rad/s)")

    def bandwidth_hz(self) -> float:
        """First 0 dB crossing of ``C P2`` [Hz]."""
        return bandwidth(self.controller, self.P2)
