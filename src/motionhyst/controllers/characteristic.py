"""The continuous loop's characteristic polynomials and its stability, from coefficients.

With the stage ``P1 = n1 / d1``, ``P2 = n2 / d2`` (eq. 1) and a continuous controller
``C = nc / dc`` (eq. 23), the loop of Fig. 3 without its link has the characteristic
polynomial ``(1 + C P2) d2 dc = d2 dc + n2 nc``: the denominator of ``w -> e =
P2 / (1 + C P2)``, common factors ``s`` cancelled against its numerator ``n2 dc``.  With
the link stuck (a spring of its initial stiffness ``kJ`` at ``y1``) it is that of
``1 + kJ P1 + C P2`` over a common denominator of ``P1`` and ``P2``.  The loop is
stable when every root of both lies in the open left half-plane
(:meth:`motionhyst.controllers.loop.Loop.check_stable`).

numpy alone: a scenario's loop is checked, and its fastest pole known, before
python-control is imported (a refusal does not wait for it), with the same
coefficients, so the same numbers, as the loop built with python-control.

Examples
--------
The paper's Table I loop (:class:`~motionhyst.plants.TwoMassStage`, eq. 23, Jenkins
``kJ = 20``):

>>> import numpy as np
>>> from motionhyst import TwoMassStage
>>> n1, n2, d = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7).polynomials()
>>> nc, dc = leadlag_coefficients(K=6.2e6, f1=60.0, f2=240.0, flp=700.0, beta=0.6)
>>> den = loop_denominator(n2, d, nc, dc)
>>> check_stable(den, stuck_characteristic(n1, d, n2, d, nc, dc, 20.0))   # no error: stable
>>> print(f"{np.max(np.abs(np.roots(den))):.4g} rad/s")                 # the fastest pole
4344 rad/s
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.polynomials import cancel_s, trim
from motionhyst.core.zoh import zoh_state_space

if TYPE_CHECKING:
    from motionhyst.controllers.sampled import SampledController

__all__ = ["as_transfer", "characteristic", "check_sampled_stable", "check_stable",
           "leadlag_coefficients", "loop_denominator", "sampled_loop_matrix", "strictly_proper",
           "stuck_characteristic"]


def as_transfer(num: ArrayLike, den: ArrayLike
                ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The coefficients python-control keeps of ``num / den``: leading zeros dropped, and a
    zero numerator over 1.

    Parameters
    ----------
    num, den : array_like
        Coefficients, highest power first (`den` not all zero).

    Examples
    --------
    >>> as_transfer([0.0, 1.0, 2.0], [0.0, 1.0, 3.0, 0.0])
    (array([1., 2.]), array([1., 3., 0.]))
    >>> as_transfer([0.0], [1.0, 2.0])
    (array([0.]), array([1.]))
    """
    n, d = trim(num), trim(den)
    return (n, np.ones(1)) if not np.any(n) else (n, d)


def leadlag_coefficients(K: float, f1: float, f2: float, flp: float, beta: float
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Numerator and denominator of the lead-lag with low-pass of eq. (23).

    ``C(s) = K (f2/f1) (s + 2 pi f1) / (s + 2 pi f2) * (2 pi flp)^2 / (s^2 + 4 beta pi flp s
    + (2 pi flp)^2)`` (:class:`~motionhyst.controllers.leadlag.LeadLagLowpass`).

    Parameters
    ----------
    K : float
        Gain [N/m].
    f1, f2 : float
        Zero and pole of the lead filter [Hz].
    flp : float
        Low-pass corner [Hz].
    beta : float
        Low-pass damping ratio [-].

    Examples
    --------
    >>> num, den = leadlag_coefficients(K=2.0, f1=1.0, f2=4.0, flp=10.0, beta=0.5)
    >>> den.size, round(float(num[-1] / den[-1]), 12)      # third order, C(0) = K
    (4, 2.0)
    """
    w1, w2, wl = 2.0 * np.pi * f1, 2.0 * np.pi * f2, 2.0 * np.pi * flp
    num = np.polymul([1.0, w1], [K * (f2 / f1) * wl**2])
    den = np.polymul([1.0, w2], [1.0, 2.0 * beta * wl, wl**2])
    return num, den


def strictly_proper(n2: ArrayLike, d2: ArrayLike, nc: ArrayLike, dc: ArrayLike) -> bool:
    """True if the loop gain ``C P2`` is strictly proper (it falls at high frequencies).

    Parameters
    ----------
    n2, d2 : array_like
        ``P2``'s numerator and denominator.
    nc, dc : array_like
        The controller's.

    Examples
    --------
    >>> strictly_proper([1.0], [1.0, 0.0, 0.0], [1.0, 1.0], [1.0])   # PD on 1 / s^2
    True
    >>> strictly_proper([1.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0])
    False
    """
    return trim(np.polymul(n2, nc)).size < trim(np.polymul(d2, dc)).size


def loop_denominator(n2: ArrayLike, d2: ArrayLike, nc: ArrayLike, dc: ArrayLike
                     ) -> NDArray[np.float64]:
    """The characteristic polynomial of the loop without its link: the denominator of
    ``w -> e = P2 / (1 + C P2) = n2 dc / (d2 dc + n2 nc)``, factors ``s`` cancelled.

    Its roots are the closed-loop poles
    (:meth:`~motionhyst.controllers.loop.Loop.closed_loop_poles`).

    Parameters
    ----------
    n2, d2 : array_like
        ``P2``'s numerator and denominator.
    nc, dc : array_like
        The controller's.

    Examples
    --------
    >>> loop_denominator([1.0], [1.0, 0.0, 0.0], [2.0, 1.0], [1.0])  # 1/s^2, C = 2 s + 1
    array([1., 2., 1.])
    """
    return cancel_s(np.polymul(n2, dc), characteristic(n2, d2, nc, dc))[1]


def characteristic(n2: ArrayLike, d2: ArrayLike, nc: ArrayLike, dc: ArrayLike
                   ) -> NDArray[np.float64]:
    """``(1 + C P2) d2 dc = d2 dc + n2 nc``, factors ``s`` not cancelled.

    Parameters
    ----------
    n2, d2 : array_like
        ``P2``'s numerator and denominator.
    nc, dc : array_like
        The controller's.

    Examples
    --------
    >>> characteristic([1.0], [1.0, 0.0, 0.0], [2.0, 1.0], [1.0])
    array([1., 2., 1.])
    """
    return np.polyadd(np.polymul(d2, dc), np.polymul(n2, nc))


def stuck_characteristic(n1: ArrayLike, d1: ArrayLike, n2: ArrayLike, d2: ArrayLike,
                         nc: ArrayLike, dc: ArrayLike, kj: float) -> NDArray[np.float64]:
    """The characteristic polynomial with the link stuck, ``w = kJ y1``: that of ``1 + kJ P1
    + C P2`` over a common denominator of ``P1`` and ``P2`` (shared by both for a two-mass
    stage).

    Parameters
    ----------
    n1, d1 : array_like
        ``P1``'s numerator and denominator.
    n2, d2 : array_like
        ``P2``'s.
    nc, dc : array_like
        The controller's.
    kj : float
        The link's initial stiffness [N/m].

    Examples
    --------
    >>> stuck_characteristic([1.0], [1.0, 0.0, 0.0], [1.0], [1.0, 0.0, 0.0], [2.0, 1.0],
    ...                      [1.0], 3.0)                      # s^2 + 2 s + 4
    array([1., 2., 4.])
    """
    d1, d2 = np.asarray(d1, float), np.asarray(d2, float)
    if d1.shape == d2.shape and np.array_equal(d1, d2):
        n1c, n2c, d = n1, n2, d1
    else:
        n1c, n2c, d = np.polymul(n1, d2), np.polymul(n2, d1), np.polymul(d1, d2)
    return np.polyadd(np.polymul(np.polyadd(d, kj * np.asarray(n1c)), dc), np.polymul(n2c, nc))


def check_stable(den: ArrayLike, stuck: ArrayLike | None = None) -> None:
    """Raise ``ValueError`` unless every root of `den` (and of `stuck`) has a negative real
    part.

    Parameters
    ----------
    den : array_like
        The loop's characteristic polynomial without its link (:func:`loop_denominator`).
    stuck : array_like, optional
        With the link stuck (:func:`stuck_characteristic`); None: the loop has no link.

    Raises
    ------
    ValueError
        One line naming the case and its rightmost pole [rad/s].

    Examples
    --------
    >>> check_stable([1.0, 2.0, 1.0])                         # (s + 1)^2
    >>> try:
    ...     check_stable([1.0, 2.0, 1.0], [1.0, -1.0, 1.0])
    ... except ValueError as exc:
    ...     print(exc)
    the controller does not stabilise the loop with the dynamic link stuck (closed-loop \
pole at 0.5+0.866j rad/s)
    """
    cases = [("", den)] if stuck is None else [("", den), (" with the dynamic link stuck",
                                                            stuck)]
    for what, poly in cases:
        p = np.roots(trim(poly))
        if p.size and np.max(p.real) >= 0:
            worst = p[np.argmax(p.real)]
            raise ValueError(f"the controller does not stabilise the loop{what} "
                             f"(closed-loop pole at {worst.real:.4g}{worst.imag:+.4g}j rad/s)")


def sampled_loop_matrix(whole: int, plant: tuple[NDArray[np.float64], ...],
                        controller: tuple[NDArray[np.float64], ...]) -> NDArray[np.float64]:
    """The state matrix of the sampled loop over one period: the plant behind its delayed
    hold, the delay line and the controller; its eigenvalues are the loop's poles ``z``.

    Parameters
    ----------
    whole : int
        Whole samples of delay ``D``.
    plant : tuple
        ``(Phi, Gamma_a, Gamma_b, C)`` of the held plant
        (:func:`~motionhyst.core.zoh.zoh_state_space`).
    controller : tuple
        ``(A, B, C, D)`` of the controller, input ``[r_k, y_k]``
        (:meth:`~motionhyst.controllers.sampled.SampledController.state_space`).

    Examples
    --------
    ``1 / s`` under ``u_k = -K y_k`` without delay: ``z = 1 - K T`` (and 0, the last sample
    held, a state of the delay line):

    >>> from motionhyst.core.zoh import zoh_state_space
    >>> whole, plant = zoh_state_space([1.0], [1.0, 0.0], 0.1)
    >>> K = np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((1, 0)), np.array([[5.0, -5.0]])
    >>> np.linalg.eigvals(sampled_loop_matrix(whole, plant, K)).round(12).tolist()
    [0.0, 0.5]
    """
    Phi, ga, gb, Cp = plant
    Ac, Bc, Cc, Dc = controller
    by, dy = Bc[:, 1], Dc[0, 1]     # the output enters with the feedback's sign
    n, nc, nd = Phi.shape[0], Ac.shape[0], whole + 1
    N = n + nc + nd
    A = np.zeros((N, N))
    iu = n + nc                      # delay line: u_{k-1}, ..., u_{k-D-1}
    # u_k = Cc xc + dy Cp x
    u_row = np.zeros(N)
    u_row[:n] = dy * Cp
    u_row[n:n + nc] = Cc[0]
    # u_{k-D}: u_k itself without whole delay, else a state of the line
    u_kd = u_row if whole == 0 else np.eye(N)[iu + whole - 1]
    A[:n] = np.outer(ga, np.eye(N)[iu + whole]) + np.outer(gb, u_kd)
    A[:n, :n] += Phi
    A[n:n + nc, :n] = np.outer(by, Cp)
    A[n:n + nc, n:n + nc] = Ac
    A[iu] = u_row
    for i in range(1, nd):
        A[iu + i, iu + i - 1] = 1.0
    return A


def check_sampled_stable(n2: ArrayLike, d2: ArrayLike, controller: SampledController,
                         stuck: tuple[ArrayLike, ArrayLike, float] | None = None) -> None:
    """Raise ``ValueError`` unless the loop of ``P2 = n2 / d2`` and the sampled `controller`
    (its hold and delay) is stable, and with the link stuck (a spring ``kJ`` at ``y1``:
    ``P2`` becomes ``n2 d1 / (d1 d2 + kJ n1 d2)``).

    numpy alone, from the coefficients: a scenario's sampled loop is checked before
    python-control is imported, as :meth:`Loop.check_stable
    <motionhyst.controllers.loop.Loop.check_stable>` checks it once built.

    Parameters
    ----------
    n2, d2 : array_like
        ``P2``'s numerator and denominator (strictly proper, at most two integrators).
    controller : SampledController
        The controller (rate, delay, feedback path).
    stuck : tuple, optional
        ``(n1, d1, kJ)``: ``P1`` and the link's initial stiffness; None: no link.

    Raises
    ------
    ValueError
        One line naming the case, its largest pole ``z``, the rate and the delay.

    Examples
    --------
    >>> from motionhyst.controllers.sampled import SampledController
    >>> c = SampledController([25.0], [1.0], sample_rate_hz=10.0)     # u_k = -25 y_k
    >>> try:
    ...     check_sampled_stable([1.0], [1.0, 0.0], c)                  # 1 / s: z = 1 - 2.5
    ... except ValueError as exc:
    ...     print(exc)
    the sampled controller does not stabilise the loop (closed-loop pole at z = -1.5+0j, \
|z| = 1.5 >= 1, at 10 Hz with 0 samples of delay)
    """
    cases = [("", n2, d2)]
    if stuck is not None:
        n1, d1, kj = stuck
        cases.append((" with the dynamic link stuck", np.polymul(n2, d1),
                      np.polyadd(np.polymul(d1, d2), kj * np.polymul(n1, d2))))
    for what, num, den in cases:
        whole, plant = zoh_state_space(num, den, controller.period, controller.delay_samples)
        z = np.linalg.eigvals(sampled_loop_matrix(whole, plant, controller.state_space()))
        if z.size and np.max(np.abs(z)) >= 1.0:
            worst = z[np.argmax(np.abs(z))]
            raise ValueError(
                f"the sampled controller does not stabilise the loop{what} (closed-loop "
                f"pole at z = {worst.real:.6g}{worst.imag:+.6g}j, |z| = {abs(worst):.6g} "
                f">= 1, at {controller.sample_rate_hz:g} Hz with "
                f"{controller.delay_samples:g} samples of delay)")
