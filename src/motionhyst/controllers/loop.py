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
A force ``f`` added to the controller's output (a hysteresis model's or a
friction feedforward) reaches ``e`` and ``y1`` as ``-w`` does (``"f->e"``, ``"f->y1"``).

With a sampled controller (:class:`~motionhyst.controllers.sampled.SampledController`,
``u_k = R(z) r_k - Y(z) y_k`` held ``d`` samples late, hold ``H``, the plant behind
the hold ``G_d(z)``, :mod:`motionhyst.core.sampling`) a sinusoid ``r`` at
``w`` gives the force's samples at ``z = e^{j w T}`` and the held force at
``w + k w_s`` for every ``k``; the transfers are those of the fundamental,
the response at ``w`` itself, exact for every ``w`` that is not a multiple of
the Nyquist frequency::

    U_d = ((R + F) r + Y P2 w) / (1 + Y G_d),   F = (m (j w)^2 + c j w) e^{j w a T}
    e   = (1 + Y Delta + P2 H (Y - R) - P2 H F) / (1 + Y G_d) r + P2 (1 + Y Delta) / (1 + Y G_d) w
    y1  = P1 H (R + F) / (1 + Y G_d) r - P1 (1 + Y Delta) / (1 + Y G_d) w

with ``Delta = G_d - P2 H`` the aliases of the held force seen at the samples
and ``a`` the feedforward's advance; ``1 - P2 H F`` is formed as
``(1 - H e^{j w a T}) + ...`` without subtracting positions.  They tend to the
continuous ones as ``T -> 0``.
"""

from __future__ import annotations

import control
import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.controllers.characteristic import (
    characteristic,
    check_sampled_stable,
    check_stable,
    sampled_loop_matrix,
    strictly_proper,
    stuck_characteristic,
)
from motionhyst.controllers.feedforward import Feedforward
from motionhyst.controllers.leadlag import bandwidth
from motionhyst.controllers.sampled import SampledController, polyval_zinv
from motionhyst.core.lti import PolyTF, cancel_s, freqresp, polysub_exact, tf_poly
from motionhyst.core.sampling import ZohEquivalent, hold_mismatch, hold_response
from motionhyst.hysteresis.base import Hysteresis
from motionhyst.plants import PLANTS, Plant, TransferPlant

__all__ = ["TRANSFERS", "Loop"]

TRANSFERS = ("r->e", "r->y1", "w->e", "w->y1", "f->e", "f->y1")


class Loop:
    """Plant, controller, hysteresis and feedforward of the paper's Fig. 3.

    Parameters
    ----------
    plant : Plant or tuple
        The stage, any plant of :mod:`motionhyst.plants` (the protocol
        :class:`~motionhyst.plants.registry.Plant`): the two-mass stage
        :class:`~motionhyst.plants.TwoMassStage`, a plant fitted to a measured
        FRF (:class:`~motionhyst.plants.ModalPlant`), the raw measured plant
        (:class:`~motionhyst.plants.MeasuredPlant`), ...; or a tuple
        ``(P1, P2)`` of python-control LTI systems (then `mass` is required for
        the feedforward; kept as a :class:`~motionhyst.plants.TransferPlant`).
    controller : python-control LTI system or SampledController
        Feedback controller ``C``, continuous or sampled
        (:class:`~motionhyst.controllers.sampled.SampledController`).
    hysteresis : Hysteresis, optional
        The dynamic link ``phi`` acting at ``y1``; None for none.
    feedforward : {"rigid-body", None} or Feedforward
        ``C_ff = M s^2`` (the paper's feedforward), no feedforward, or the
        setpoint feedforward with acceleration, viscous and Coulomb terms
        (:class:`~motionhyst.controllers.feedforward.Feedforward`, its mass
        taken from the plant unless given).
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
        if isinstance(plant, tuple | list):
            try:
                P1, P2 = plant
            except ValueError:
                raise TypeError("plant must be a plant of motionhyst.plants or a tuple "
                                "(P1, P2)") from None
            plant = TransferPlant(P1, P2, mass)
        elif not isinstance(plant, Plant):
            raise TypeError(f"plant must be a plant of motionhyst.plants ({', '.join(PLANTS)}) "
                            f"or a tuple (P1, P2), got {type(plant).__name__}")
        if plant.force_offset:
            raise ValueError(f"the closed loop's analyses take no constant force on the plant "
                             f"(force_offset = {plant.force_offset:g} N); the open-loop time "
                             f"runs do")
        if getattr(plant, "force_drift", 0.0):
            raise ValueError(f"the closed loop takes no drifting force on the plant "
                             f"(force_drift = {plant.force_drift:g} N/s); the open-loop time "
                             f"runs do")
        if getattr(plant, "c_skew", 0.0):
            raise ValueError(f"the closed loop takes no viscous friction by direction on the "
                             f"plant (c_skew = {plant.c_skew:g} N s/m); the open-loop time "
                             f"runs do")
        P1, P2 = plant.P1, plant.P2
        mass = plant.M if mass is None else mass
        if isinstance(feedforward, Feedforward):
            ff = feedforward
            if ff.mass is None and (mass is None or not mass > 0):
                raise ValueError("rigid-body feedforward needs the mass M > 0")
            ff = ff.with_mass(mass) if ff.mass is None else ff
            feedforward = "rigid-body" if ff.mass > 0 else None
        elif feedforward not in ("rigid-body", None):
            raise ValueError(f"unknown feedforward {feedforward!r}; use 'rigid-body' or None")
        elif feedforward == "rigid-body":
            if mass is None or not mass > 0:
                raise ValueError("rigid-body feedforward needs the mass M > 0")
            ff = Feedforward(mass=float(mass))
        else:
            ff = None
        self.ff = ff
        self.sampled = controller if isinstance(controller, SampledController) else None
        if ff is not None and ff.advance_samples and self.sampled is None:
            raise ValueError("the feedforward's advance_samples needs a sampled controller")
        self.plant = plant
        self.P1, self.P2 = P1, P2
        self.controller = controller
        self.hysteresis = hysteresis
        self.feedforward = feedforward
        self.M = float(mass) if mass is not None else None
        self.hysteresis_feedforward = hysteresis_feedforward
        self.is_lti = not any(isinstance(s, control.FrequencyResponseData)
                              for s in (P1, P2, controller))
        self._poles: NDArray[np.complex128] | None = None
        #: the sampled loop's responses (:class:`SampledParts`), None for a continuous controller
        self.sampled_parts: SampledParts | None = None
        if self.sampled is not None:
            if not self.is_lti:
                raise ValueError("a sampled controller needs a plant model: the samples alias "
                                 "the plant's response above the measured lines; fit the data "
                                 '([plant] use = "fit")')
            self._poly = None
            self.sampled_parts = SampledParts(self)
        else:
            self._poly = self._closed_loop_polys() if self.is_lti else None

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
        if not strictly_proper(n2, d2, nc, dc):
            raise ValueError("the loop gain C P2 must be strictly proper (a pure derivative "
                             "needs a plant that falls at least twice as fast)")
        char = characteristic(n2, d2, nc, dc)  # (1 + C P2) d2 dc
        if self.ff is not None:
            # 1 - P2 C_ff = (d2 - C_ff n2) / d2; C + C_ff = (nc + C_ff dc) / dc,
            # C_ff = cs s^4 + cj s^3 + m s^2 + c s (m = M: the paper's rigid-body feedforward)
            ff = self.ff
            c_ff = np.trim_zeros([ff.snap, ff.jerk, ff.mass, ff.viscous, 0.0], "f")
            ff_num = polysub_exact(d2, np.polymul(n2, c_ff))
            cff = np.polyadd(nc, np.polymul(dc, c_ff))
        else:
            ff_num, cff = d2, nc
        out = {
            "r->e": cancel_s(np.polymul(ff_num, dc), char),
            "r->y1": cancel_s(np.polymul(np.polymul(n1, d2), cff), np.polymul(d1, char)),
            "w->e": cancel_s(np.polymul(n2, dc), char),  # as loop_denominator
            "w->y1": cancel_s(-np.polymul(np.polymul(n1, d2), dc), np.polymul(d1, char)),
            "f->e": cancel_s(-np.polymul(n2, dc), char),
            "f->y1": cancel_s(np.polymul(np.polymul(n1, d2), dc), np.polymul(d1, char)),
        }
        return {k: PolyTF(*v) for k, v in out.items()}

    def transfer(self, name: str, omega: ArrayLike) -> NDArray[np.complex128]:
        """Frequency response of a closed-loop transfer at `omega` [rad/s].

        Parameters
        ----------
        name : {"r->e", "r->y1", "w->e", "w->y1", "f->e", "f->y1"}
            From reference, hysteresis force or a feedforward force (added to
            the controller's output) to tracking error or ``y1``.  For a
            sampled controller the response at `omega` itself (the fundamental),
            the feedforward force sampled, advanced and held as the controller's.
        omega : array_like
            Angular frequencies [rad/s]; 0 is allowed for continuous LTI loops.
        """
        if name not in TRANSFERS:
            raise ValueError(f"unknown transfer {name!r}; one of {', '.join(TRANSFERS)}")
        w = np.asarray(omega, dtype=float)
        if self.sampled_parts is not None:
            return self.sampled_parts.transfer(name, w)
        if self._poly is not None:
            return self._poly[name](w)
        P1, P2 = freqresp(self.P1, w), freqresp(self.P2, w)
        C = freqresp(self.controller, w)
        Cff = 0.0 if self.ff is None else self.ff.linear_response(w)
        sens = 1.0 / (1.0 + C * P2)
        return {"r->e": (1.0 - P2 * Cff) * sens, "r->y1": P1 * (C + Cff) * sens,
                "w->e": P2 * sens, "w->y1": -P1 * sens, "f->e": -P2 * sens,
                "f->y1": P1 * sens}[name]

    def transfer_tf(self, name: str) -> control.TransferFunction:
        """A closed-loop transfer as a python-control transfer function (LTI loops only).

        Parameters
        ----------
        name : str
            Which transfer, one of :data:`TRANSFERS` (``"r->e"``: reference to error, ...).
        """
        if self._poly is None:
            raise ValueError("closed-loop transfer functions need LTI plant and controller")
        if name not in TRANSFERS:
            raise ValueError(f"unknown transfer {name!r}; one of {', '.join(TRANSFERS)}")
        return self._poly[name].tf()

    def closed_loop_poles(self) -> NDArray[np.complex128]:
        """Poles of ``1 + C P2`` (LTI loops only; ValueError for measured data).

        For a sampled controller the poles ``z_i`` of the sampled loop, given as
        ``ln(z_i) / T`` [rad/s] (stable: real part < 0).
        """
        if self.sampled_parts is not None:
            if self._poles is None:
                self._poles = self.sampled_parts.poles()
            return self._poles.copy()
        if self._poly is None:
            raise ValueError("closed-loop poles, the time simulation and the steady state need "
                             "LTI plant and controller; a raw measured plant has none: fit it "
                             '([plant] use = "fit")')
        if self._poles is None:
            self._poles = np.roots(self._poly["w->e"].den)
        return self._poles.copy()

    def transfer_key(self) -> tuple | None:
        """A key equal for continuous LTI loops whose closed-loop transfers are the same (the
        coefficients of their polynomials), None for another loop.

        Loops that differ only in their link (a study's samples of ``hysteresis.k``) share
        it, and with it what :func:`~motionhyst.analysis.steady.periodic_steady_state`
        computes once a frequency.

        Examples
        --------
        >>> from motionhyst import Dahl, Loop, default_scenario
        >>> loop = default_scenario().loop()
        >>> other = Loop(loop.plant, loop.controller, Dahl(k=20.0, fc=0.05), loop.feedforward)
        >>> other.transfer_key() == loop.transfer_key()
        True
        """
        key = self.__dict__.get("_transfer_key")
        if key is None and self._poly is not None:
            key = self._transfer_key = tuple((name, tf.num.tobytes(), tf.den.tobytes())
                                             for name, tf in sorted(self._poly.items()))
        return key

    def check_stable(self) -> None:
        """Raise ``ValueError`` unless the linear loop is stable.

        Checked without the dynamic link and with it stuck (a spring of the
        hysteresis's initial stiffness at ``y1``), the two linear extremes of
        the element.  Only LTI loops can be checked.
        """
        if self.sampled_parts is not None:
            self.sampled_parts.check_stable()
            return
        if self._poly is None:
            return
        stuck = None
        if self.hysteresis is not None:
            n1, d1 = tf_poly(self.P1)
            n2, d2 = tf_poly(self.P2)
            nc, dc = tf_poly(self.controller)
            stuck = stuck_characteristic(n1, d1, n2, d2, nc, dc,
                                         self.hysteresis.initial_stiffness)
        check_stable(self._poly["w->e"].den, stuck)

    def bandwidth_hz(self) -> float:
        """First 0 dB crossing of ``C P2`` [Hz] (of ``Y(z) G_d(z)`` for a sampled controller)."""
        if self.sampled_parts is not None:
            return self.sampled_parts.bandwidth_hz()
        return bandwidth(self.controller, self.P2)

    def open_loop(self, omega: ArrayLike) -> NDArray[np.complex128]:
        """The loop gain ``L = C P2`` without the link at `omega` [rad/s].

        For a sampled controller ``L = Y(e^{j w T}) G_d(e^{j w T})``, hold and
        delay included: the loop the stability margins are taken of.

        Parameters
        ----------
        omega : array_like
            Angular frequencies [rad/s].
        """
        w = np.asarray(omega, dtype=float)
        if self.sampled_parts is not None:
            return self.sampled_parts.open_loop(w)
        return freqresp(self.controller, w) * freqresp(self.P2, w)


class SampledParts:
    """The parts of a loop with a sampled controller and its fundamental responses.

    Parameters
    ----------
    loop : Loop
        A loop whose controller is a :class:`~motionhyst.controllers.sampled.SampledController`.

    Attributes
    ----------
    zoh : ZohEquivalent
        ``G_d``: ``P2`` behind the controller's delayed hold.
    P1, P2 : PolyTF
        The plant's transfers (callables of ``omega``).
    Pf2 : PolyTF or None
        The plant's flexible part of ``P2`` when it has one.
    """

    def __init__(self, loop: Loop) -> None:
        c = loop.sampled
        self.loop = loop
        self.c = c
        self.T = c.period
        self.d = c.delay_samples
        self.zoh = ZohEquivalent(loop.P2, self.T, self.d)
        self.a = 0.0 if loop.ff is None else loop.ff.advance_samples
        self._last = None
        n2, d2 = tf_poly(loop.P2)
        self.P2 = PolyTF(n2, d2)
        n1, d1 = tf_poly(loop.P1)
        self.P1 = PolyTF(n1, d1)
        pf2 = loop.plant.Pf2
        self.Pf2 = None if pf2 is None else PolyTF(*tf_poly(pf2))
        if not c.one_dof:  # Y - R as one ratio, its coefficients exact
            num = np.polysub(np.convolve(c.y_num, c.r_den)[::-1],
                             np.convolve(c.r_num, c.y_den)[::-1])[::-1]
            self._y_minus_r = (num, np.convolve(c.y_den, c.r_den))

    def _parts(self, w):
        w = np.asarray(w, dtype=float)
        key = (w.shape, w.tobytes())
        if self._last is not None and self._last[0] == key:  # the transfers of one analysis
            return self._last[1]
        zinv = np.exp(-1j * w * self.T)
        R, Y = self.c.response(w)
        P2 = self.P2(w)
        H = hold_response(w, self.T, self.d)
        Gd = self.zoh(w)
        self._last = (key, (zinv, R, Y, P2, H, Gd))
        return self._last[1]

    def open_loop(self, w: ArrayLike) -> NDArray[np.complex128]:
        """``L = Y G_d`` at `w` [rad/s].

        Parameters
        ----------
        w : array_like
            Angular frequencies [rad/s].
        """
        _, _, Y, _, _, Gd = self._parts(w)
        return Y * Gd

    def process_sensitivity(self, w: ArrayLike) -> NDArray[np.complex128]:
        """``G_d / (1 + Y G_d)``: the output's samples per unit force added to ``u_k``.

        The discrete process sensitivity, from a force added to the controller's
        output samples to the measured output's samples (``1 / Y(1)`` at ``w = 0``
        for a plant with integrators).

        Parameters
        ----------
        w : array_like
            Angular frequencies [rad/s], up to the Nyquist frequency.
        """
        w = np.asarray(w, dtype=float)
        Y = self.c.feedback_response(w)
        with np.errstate(divide="ignore", invalid="ignore"):
            Gd = self.zoh(w)
            out = Gd / (1.0 + Y * Gd)
        return np.where(~np.isfinite(Gd), 1.0 / Y, out)

    def transfer(self, name: str, w: ArrayLike) -> NDArray[np.complex128]:
        """The fundamental response `name` (see :meth:`Loop.transfer`).

        Parameters
        ----------
        name : str
            One of :data:`TRANSFERS`.
        w : array_like
            Angular frequencies [rad/s].
        """
        loop, T = self.loop, self.T
        zinv, R, Y, P2, H, Gd = self._parts(w)
        den = 1.0 + Y * Gd
        adv = np.exp(1j * w * T * self.a)
        if name in ("f->e", "f->y1"):
            out = H * adv / den
            return -P2 * out if name == "f->e" else self.P1(w) * out
        if name in ("w->e", "w->y1"):
            lift = (1.0 + Y * (Gd - P2 * H)) / den
            return P2 * lift if name == "w->e" else -self.P1(w) * lift
        ff = loop.ff
        F = 0.0 if ff is None else ff.linear_response(w) * adv
        if name == "r->y1":
            return self.P1(w) * H * (R + F) / den
        # r->e: 1 + Y Delta + P2 H (Y - R) - P2 H F, the last without subtracting positions
        num = 1.0 + Y * (Gd - P2 * H)
        if not self.c.one_dof:
            yr_num, yr_den = self._y_minus_r
            num = num + P2 * H * polyval_zinv(yr_num, zinv) / polyval_zinv(yr_den, zinv)
        if ff is None:
            return num / den
        s = 1j * w
        lag = hold_mismatch(w, T, self.d - self.a)            # 1 - H e^{j w a T}
        He = 1.0 - lag
        m = ff.mass
        if self.Pf2 is not None and loop.M:
            # He m s^2 P2 = He (m / M) (1 - M s^2 Pf2); 1 - He (m / M) = lag + He (1 - m / M)
            num = (num - 1.0) + lag + He * (1.0 - m / loop.M) + He * m * s * s * self.Pf2(w)
        else:
            num = num - He * m * s * s * P2
        return (num - He * (((ff.snap * s + ff.jerk) * s * s + ff.viscous) * s) * P2) / den

    def poles(self) -> NDArray[np.complex128]:
        """``ln(z) / T`` of the sampled loop's poles ``z`` (the link left out)."""
        z = self._poles_z(self.loop.P2).astype(complex)
        with np.errstate(all="ignore"):  # poles at z = 0 (delays) are at -inf
            return np.log(z) / self.T

    def _poles_z(self, P2) -> NDArray[np.complex128]:
        """Eigenvalues of the sampled loop around ``P2``: plant, delay line and controller."""
        G = ZohEquivalent(P2, self.T, self.d)
        return np.linalg.eigvals(sampled_loop_matrix(G.whole, G.state_space(),
                                                     self.c.state_space()))

    def check_stable(self) -> None:
        """Raise ``ValueError`` unless the sampled loop is stable (link absent and stuck),
        from the plant's and the controller's coefficients (:func:`check_sampled_stable`: the
        check a scenario makes before the loop is built)."""
        loop = self.loop
        stuck = None
        if loop.hysteresis is not None:
            stuck = (*tf_poly(loop.P1), loop.hysteresis.initial_stiffness)
        check_sampled_stable(*tf_poly(loop.P2), self.c, stuck)

    def bandwidth_hz(self) -> float:
        """First frequency below Nyquist where ``|Y G_d|`` falls through 1 [Hz]."""
        nyq = self.c.nyquist_hz
        f = np.geomspace(min(1e-3, nyq * 1e-6), nyq * (1 - 1e-9), 4000)
        lm = np.log(np.abs(self.open_loop(2 * np.pi * f)))
        idx = np.nonzero((lm[:-1] > 0) & (lm[1:] <= 0))[0]
        if idx.size == 0:
            return float("nan")
        i = int(idx[0])
        from scipy.optimize import brentq

        g = lambda x: float(np.log(np.abs(self.open_loop(np.array([2 * np.pi * x]))[0])))  # noqa: E731
        return float(brentq(g, f[i], f[i + 1], xtol=1e-13 * f[i], rtol=1e-14))
