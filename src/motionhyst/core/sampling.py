"""A continuous plant seen by a digital controller: zero-order hold, delay, sampling.

The controller's output ``u_k``, computed from the samples at ``t_k = k T``, is
applied from ``t_k + d T`` on and held until the next update (``d`` samples of
delay, fractional allowed).  The held force has the Fourier transform of the
samples' times the hold's response::

    H(s) = e^{-s d T} (1 - e^{-s T}) / (s T)            (H(0) = 1)

and the plant's output sampled at ``t_k`` answers the samples ``u_k`` with the
pulse transfer function of the plant behind the hold (the modified z-transform
for a fractional delay)::

    G_d(e^{s T}) = sum_k P(s + j k w_s) H(s + j k w_s),     w_s = 2 pi / T

which for an integer ``d`` is ``c2d(P, T, "zoh") z^-d``.  :class:`ZohEquivalent`
evaluates it in closed form, exactly: with ``d = D + phi`` (``0 <= phi < 1``)
the state over one period is ``x_{k+1} = Phi x_k + Gamma_a u_{k-D-1} +
Gamma_b u_{k-D}``, the older sample acting for ``phi T`` first.  The plant's
rigid-body part (its poles at ``s = 0``) is taken apart and evaluated with
``z - 1 = expm1(j w T)``, so that ``G_d`` keeps its relative accuracy at low
frequency, where ``(zI - Phi)^-1`` of a double integrator would lose
``(w T)^-2`` of it.

Examples
--------
>>> import numpy as np
>>> import control
>>> P = control.tf([1.0], [2.0, 0.0, 0.0])                 # 1 / (2 s^2)
>>> G = ZohEquivalent(P, period=1e-3)
>>> Gd = control.c2d(P, 1e-3, "zoh")
>>> w = np.array([10.0, 1000.0])
>>> bool(np.allclose(G(w), Gd(np.exp(1j * w * 1e-3)), rtol=1e-9))
True
>>> complex(hold_response(0.0, 1e-3, 1.5))                 # passes DC unchanged
(1+0j)
"""

from __future__ import annotations

import math

import control
import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.lti import expm_small
from motionhyst.core.zoh import canonical_state_space, held_rest, held_state_space, rigid_split

__all__ = ["HeldInputFilter", "ZohEquivalent", "hold_mismatch", "hold_response",
           "unit_circle_minus_one"]


def unit_circle_minus_one(theta: ArrayLike) -> NDArray[np.complex128]:
    """``e^{j theta} - 1`` to full relative accuracy near ``theta = 0``.

    Parameters
    ----------
    theta : array_like
        Angles [rad].

    Examples
    --------
    >>> from motionhyst.core.sampling import unit_circle_minus_one
    >>> complex(unit_circle_minus_one(1e-9))               # not 1e-9j plus round-off
    (-5e-19+1e-09j)
    """
    th = np.asarray(theta, dtype=float)
    return -2.0 * np.sin(0.5 * th) ** 2 + 1j * np.sin(th)


def hold_response(omega: ArrayLike, period: float, delay_samples: float = 0.0
                  ) -> NDArray[np.complex128]:
    """Zero-order hold with delay, ``H(j w) = e^{-j w d T} (1 - e^{-j w T}) / (j w T)``.

    Parameters
    ----------
    omega : array_like
        Angular frequencies [rad/s]; 0 gives 1.
    period : float
        Sampling period ``T`` [s].
    delay_samples : float
        Delay ``d`` of the held output, in samples (fractional allowed).

    Returns
    -------
    ndarray of complex
        The hold's response relative to a sample sequence of unit spectrum
        (``H -> 1`` as ``T -> 0``).

    Examples
    --------
    >>> from motionhyst.core.sampling import hold_response
    >>> h = complex(hold_response(2 * 3.141592653589793 * 500.0, 1e-3))   # at Nyquist
    >>> round(abs(h), 4), round(float(np.degrees(np.angle(h))), 1)        # 2 / pi, -90 deg
    (0.6366, -90.0)
    """
    w = np.asarray(omega, dtype=float)
    th = w * period
    with np.errstate(divide="ignore", invalid="ignore"):
        zoh = np.where(th == 0.0, 1.0 + 0j, -np.conj(unit_circle_minus_one(th))
                       / np.where(th == 0.0, 1.0, 1j * th))
    return zoh * np.exp(-1j * th * delay_samples)


def hold_mismatch(omega: ArrayLike, period: float, lag_samples: float = 0.0
                  ) -> NDArray[np.complex128]:
    """``1 - H(j w)`` for a hold lagging `lag_samples`, to full accuracy at low frequency.

    ``H = e^{-j w l T} (1 - e^{-j w T}) / (j w T)``: the part of a sampled,
    held and delayed feedforward that does not arrive as computed.  With
    ``l = -1/2`` (the feedforward advanced by the delay and half a sample) it
    is of second order in ``w T``, of first order otherwise.

    Parameters
    ----------
    omega : array_like
        Angular frequencies [rad/s].
    period : float
        Sampling period ``T`` [s].
    lag_samples : float
        ``l``: the delay minus the feedforward's advance, in samples (may be negative).

    Examples
    --------
    >>> from motionhyst.core.sampling import hold_mismatch
    >>> w, T = 2 * np.pi * 5.0, 1e-4
    >>> round(abs(complex(hold_mismatch(w, T, -0.5))) / (w * T) ** 2, 6)   # (w T)^2 / 24
    0.041667
    """
    th = np.asarray(omega, dtype=float) * period
    small = np.abs(th) < 0.05
    ts = np.where(small, th, 0.0)
    # 1 - q, q = (1 - e^{-j th}) / (j th): j (th - sin th) / (j th) - 2 sin^2(th / 2) / (j th)
    series = ts**2 / 6.0 - ts**4 / 120.0 + ts**6 / 5040.0 - ts**8 / 362880.0
    with np.errstate(divide="ignore", invalid="ignore"):
        direct = (th - np.sin(th)) / np.where(small, 1.0, th)
        sin2 = np.where(th == 0.0, 0.0, 2.0 * np.sin(0.5 * th) ** 2 / np.where(th == 0, 1.0, th))
    one_minus_q = np.where(small, series, direct) + 1j * sin2
    q = 1.0 - one_minus_q
    return one_minus_q - q * unit_circle_minus_one(-th * lag_samples)


class ZohEquivalent:
    """Pulse transfer function ``G_d(z)`` of a plant behind a delayed zero-order hold.

    Parameters
    ----------
    plant : python-control LTI system
        Strictly proper SISO continuous plant ``P`` (at most two poles at ``s = 0``).
    period : float
        Sampling period ``T`` [s].
    delay_samples : float
        Delay ``d >= 0`` of the held input in samples (fractional allowed).

    Attributes
    ----------
    a2, a1 : float
        Rigid-body part ``a2 / s^2 + a1 / s`` of ``P``.

    Examples
    --------
    The ZOH equivalent with one and a half samples of delay lies between those of one
    and two samples:

    >>> import numpy as np
    >>> import control
    >>> from motionhyst.core.sampling import ZohEquivalent
    >>> P = control.tf([1.0], [1.0, 1.0, 0.0])             # 1 / (s (s + 1))
    >>> w = np.array([1.0])
    >>> g = [abs(np.angle(ZohEquivalent(P, 0.1, d)(w)[0])) for d in (1.0, 1.5, 2.0)]
    >>> bool(g[0] < g[1] < g[2])
    True
    """

    def __init__(self, plant, period: float, delay_samples: float = 0.0) -> None:
        if not (math.isfinite(period) and period > 0):
            raise ValueError(f"the sampling period must be finite and > 0, got {period!r}")
        if not (math.isfinite(delay_samples) and delay_samples >= 0):
            raise ValueError(f"delay_samples must be finite and >= 0, got {delay_samples!r}")
        if isinstance(plant, control.StateSpace):
            plant = control.ss2tf(plant)
        if not isinstance(plant, control.TransferFunction) or plant.isdtime(strict=True):
            raise TypeError("the plant behind the hold must be a continuous python-control "
                            "LTI system (measured frequency data have no response above the "
                            "measured lines, which the samples alias)")
        num = np.asarray(plant.num[0][0], float)
        den = np.asarray(plant.den[0][0], float)
        if np.trim_zeros(num, "f").size >= np.trim_zeros(den, "f").size:
            raise ValueError("the plant behind the hold must be strictly proper")
        self.period = float(period)
        self.delay_samples = float(delay_samples)
        self.whole = math.floor(self.delay_samples)
        self.phi = self.delay_samples - self.whole
        self.a2, self.a1, rest_num, rest_den = rigid_split(num, den)
        self._rest = None
        if np.any(rest_num != 0.0):
            A, B, C, _ = canonical_state_space(rest_num, rest_den)  # python-control's tf2ss
            self._rest = held_rest(A, B, C, self.period, self.phi, expm_small)
            Phi, Ebga, gb, _ = self._rest
            # partial fractions over Phi's eigenvalues: sum (ra z^-1 + rb) / (z - lambda)
            lam, V = np.linalg.eig(Phi)
            self._modal = None
            if np.linalg.cond(V) < 1e8:
                cv = C[0] @ V
                self._modal = (lam, cv * np.linalg.solve(V, Ebga), cv * np.linalg.solve(V, gb))

    def state_space(self) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                   NDArray[np.float64], NDArray[np.float64]]:
        """``(Phi, Gamma_a, Gamma_b, C)`` of the sampled plant.

        ``x_{k+1} = Phi x_k + Gamma_a u_{k-D-1} + Gamma_b u_{k-D}``, ``y_k = C x_k``,
        ``D`` = :attr:`whole` samples; the rigid-body states first.

        Examples
        --------
        >>> import control
        >>> from motionhyst.core.sampling import ZohEquivalent
        >>> Phi, ga, gb, C = ZohEquivalent(control.tf([1.0], [1.0, 0.0]), 0.1, 0.25).state_space()
        >>> Phi.tolist(), ga.tolist(), gb.tolist(), C.tolist()      # 1 / s
        ([[1.0]], [0.025], [0.075], [1.0])
        """
        return held_state_space(self.a2, self.a1, self._rest, self.period, self.phi)

    def __call__(self, omega: ArrayLike) -> NDArray[np.complex128]:
        """``G_d(e^{j w T})``, the delay included.

        Parameters
        ----------
        omega : array_like
            Angular frequencies [rad/s] (> 0 for a plant with integrators).
        """
        w = np.asarray(omega, dtype=float)
        th = w.ravel() * self.period
        zm1 = unit_circle_minus_one(th)              # z - 1
        z = 1.0 + zm1
        zinv = np.exp(-1j * th)
        T, phi = self.period, self.phi
        out = np.zeros(th.shape, dtype=complex)
        if self.a2 or self.a1:
            tb = (1.0 - phi) * T
            g1 = (phi * T) ** 2 / 2.0 + tb * phi * T        # Gamma_a of 1/s^2, position
            g1 = g1 * zinv + tb**2 / 2.0
            g2 = phi * T * zinv + tb                          # velocity
            with np.errstate(divide="ignore", invalid="ignore"):
                out += self.a2 * (g1 * zm1 + T * g2) / zm1**2 + self.a1 * g2 / zm1
        if self._rest is not None and self._modal is not None:
            lam, ra, rb = self._modal
            out += np.sum((ra * zinv[:, None] + rb) / (z[:, None] - lam), axis=1)
        elif self._rest is not None:
            Phi, ga, gb, C = self._rest
            n = Phi.shape[0]
            M = z[:, None, None] * np.eye(n) - Phi
            g = ga[None, :] * zinv[:, None] + gb[None, :]
            out += np.linalg.solve(M, g[..., None])[..., 0] @ C
        return (out * zinv**self.whole).reshape(w.shape)


class HeldInputFilter:
    """A strictly proper filter applied exactly to samples held from ``t_k + d T`` on.

    A controller's output ``u_k`` acts on the plant as a staircase, held
    ``d`` samples late; filtering the staircase exactly is filtering the
    samples with the filter's pulse transfer function behind the delayed hold
    (:class:`ZohEquivalent`), evaluated here in time scaled by `omega0` for
    conditioning.  The output is the filtered staircase at ``t_k``; the filter
    starts in steady state for the first sample held since ``-inf``.

    Parameters
    ----------
    zeros, poles : array_like
        Zeros and poles [rad/s] (conjugate pairs complete), fewer zeros than poles, no
        pole at 0.
    gain : float
        Gain of the zero-pole-gain form.
    period : float
        Sampling period ``T`` [s].
    delay_samples : float
        ``d >= 0`` [samples].
    omega0 : float
        Time scale [rad/s] (e.g. the filter's cut-off).

    Examples
    --------
    A 10 Hz low-pass seeing a step that a controller at 1 kHz applies one sample late:

    >>> import numpy as np
    >>> from motionhyst.core.sampling import HeldInputFilter
    >>> wc = 2 * np.pi * 10.0
    >>> f = HeldInputFilter([], [-wc], wc, 1e-3, 1.0, wc)
    >>> y = f(np.r_[0.0, np.ones(3)])                 # the step computed at t_1, applied at t_2
    >>> np.round(y, 6).tolist()                       # 1 - exp(-wc (t - t_2)) for t >= t_2
    [0.0, 0.0, 0.0, 0.060899]
    """

    def __init__(self, zeros: ArrayLike, poles: ArrayLike, gain: float, period: float,
                 delay_samples: float, omega0: float) -> None:
        z = np.asarray(zeros, dtype=complex) / omega0
        p = np.asarray(poles, dtype=complex) / omega0
        if z.size >= p.size:
            raise ValueError("the filter must be strictly proper")
        if np.any(p == 0):
            raise ValueError("the filter must not have a pole at s = 0")
        g = float(gain) * omega0 ** (z.size - p.size)
        num = np.real(np.poly(z)) * g if z.size else np.array([g])
        den = np.real(np.poly(p))
        self.zoh = ZohEquivalent(control.tf(num, den), omega0 * float(period),
                                 float(delay_samples))
        Phi, ga, gb, C = self.zoh.state_space()
        self._mats = (Phi, ga, gb, C)
        n = Phi.shape[0]
        # steady state for a unit input held forever: x = Phi x + ga + gb
        self._x_unit = np.linalg.solve(np.eye(n) - Phi, ga + gb)

    def __call__(self, u: ArrayLike) -> NDArray[np.float64]:
        """The filtered staircase at the sampling instants.

        Parameters
        ----------
        u : array_like
            The samples ``u_k`` (1-D).
        """
        Phi, ga, gb, C = self._mats
        uu = np.asarray(u, dtype=float)
        D = self.zoh.whole
        pad = np.concatenate([np.full(D + 1, uu[0]), uu])
        new = pad[1:uu.size + 1]                      # u_{k-D}
        old = pad[:uu.size]                           # u_{k-D-1}
        x = self._x_unit * uu[0]
        out = np.empty(uu.size)
        drive = np.outer(old, ga) + np.outer(new, gb)
        for k in range(uu.size):
            out[k] = C @ x
            x = Phi @ x + drive[k]
        return out
