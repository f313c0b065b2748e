"""A plant behind a delayed zero-order hold, in state space, from its coefficients.

The controller's output ``u_k`` is applied from ``t_k + d T`` on and held for a period
(:mod:`motionhyst.core.sampling`); with ``d = D + phi`` (``0 <= phi < 1``) the plant's
state over one period is::

    x_{k+1} = Phi x_k + Gamma_a u_{k-D-1} + Gamma_b u_{k-D},     y_k = C x_k

the older sample acting for ``phi T`` first.  The plant's rigid-body part (its poles at
``s = 0``, at most two) is taken apart (:func:`rigid_split`) and held in closed form; the
rest through the exponential of its realisation (:func:`held_rest`).
:class:`~motionhyst.core.sampling.ZohEquivalent` evaluates ``G_d(z)`` with these; here
numpy alone (:func:`zoh_state_space`) gives the matrices a stability check of a sampled
loop needs before python-control or a compiled kernel is loaded.

Examples
--------
A double integrator ``1 / s^2`` held one and a half samples late:

>>> whole, (Phi, ga, gb, C) = zoh_state_space([1.0], [1.0, 0.0, 0.0], 0.1, 1.5)
>>> whole, Phi.tolist(), C.tolist()
(1, [[1.0, 0.1], [0.0, 1.0]], [1.0, 0.0])
>>> [round(float(x), 6) for x in ga + gb]                  # a whole sample's input
[0.005, 0.1]
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["canonical_state_space", "expm_taylor", "held_rest", "held_state_space",
           "rigid_split", "zoh_state_space"]

Matrices = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64],
                 NDArray[np.float64]]


def rigid_split(num: ArrayLike, den: ArrayLike
                ) -> tuple[float, float, NDArray[np.float64], NDArray[np.float64]]:
    """``num / den = a2 / s^2 + a1 / s + rest``: ``a2``, ``a1`` and the rest's polynomials.

    Parameters
    ----------
    num, den : array_like
        A strictly proper plant, highest power first.

    Raises
    ------
    ValueError
        More than two integrators.

    Examples
    --------
    >>> a2, a1, rest_num, rest_den = rigid_split([1.0], [2.0, 4.0, 0.0])   # 1 / (2 s (s + 2))
    >>> float(a2), float(a1), rest_num.tolist(), rest_den.tolist()   # 1/(4 s) - 1/(4 (s + 2))
    (0.0, 0.25, [-0.5], [2.0, 4.0])
    """
    num = np.trim_zeros(np.asarray(num, float), "f")
    den = np.trim_zeros(np.asarray(den, float), "f")
    m = 0
    while den.size > 1 and den[-1] == 0.0:
        den, m = den[:-1], m + 1
    while m > 0 and num.size > 1 and num[-1] == 0.0:
        num, m = num[:-1], m - 1
    if m > 2:
        raise ValueError("a plant with more than two integrators cannot be sampled here")
    # Taylor coefficients of num / den0 at s = 0: c0, c1
    n0 = num[-1]
    n1 = num[-2] if num.size > 1 else 0.0
    d0, d1 = den[-1], (den[-2] if den.size > 1 else 0.0)
    c0 = n0 / d0
    c1 = (n1 - c0 * d1) / d0
    a = {2: (c0, c1), 1: (0.0, c0), 0: (0.0, 0.0)}[m]
    # rest = num / (s^m den0) - a2 / s^2 - a1 / s, over s^m den0; the low coefficients vanish
    sub = np.zeros(1)
    if m == 2:
        sub = np.polyadd(np.polymul([a[1], a[0]], den), np.zeros(1))
    elif m == 1:
        sub = a[1] * den
    rest_num = np.polysub(num, sub)
    if m:
        rest_num = rest_num[:-m] if rest_num.size > m else np.zeros(1)
    return a[0], a[1], rest_num, den


def canonical_state_space(num: ArrayLike, den: ArrayLike) -> Matrices:
    """The controllable canonical realisation ``A, B, C, D`` of ``num / den``, laid out as
    :func:`scipy.signal.tf2ss` (and python-control without slycot) lay it out.

    Both are divided by ``den``'s leading coefficient, and the numerator's leading
    coefficients of magnitude up to ``1e-14`` are dropped then, as scipy drops them.

    Parameters
    ----------
    num, den : array_like
        A proper ``num / den``, highest power first (``den`` not all zero).

    Examples
    --------
    >>> A, B, C, D = canonical_state_space([1.0, 3.0, 3.0], [1.0, 2.0, 1.0])
    >>> A.tolist(), B.tolist(), C.tolist(), D.tolist()
    ([[-2.0, -1.0], [1.0, 0.0]], [[1.0], [0.0]], [[1.0, 2.0]], [[1.0]])
    """
    den = np.trim_zeros(np.atleast_1d(np.asarray(den, float)), "f")
    num = np.atleast_1d(np.asarray(num, float)) / den[0]
    den = den / den[0]
    lead = 0
    while lead < num.size - 1 and abs(num[lead]) <= 1e-14:
        lead += 1
    num = num[lead:]
    k = den.size
    if num.size > k:
        raise ValueError("improper transfer function: the numerator is longer")
    num = np.concatenate([np.zeros(k - num.size), num])
    if k == 1:
        return np.zeros((1, 1)), np.zeros((1, 1)), np.zeros((1, 1)), num.reshape(1, 1)
    A = np.vstack([-den[1:][None, :], np.eye(k - 2, k - 1)])
    B = np.eye(k - 1, 1)
    C = (num[1:] - num[0] * den[1:])[None, :]
    return A, B, C, np.array([[num[0]]])


def expm_taylor(M: ArrayLike) -> NDArray[np.float64]:
    """``exp(M)`` of a small square matrix by the algorithm of
    :func:`motionhyst.core.lti.expm_small` (scaling and squaring of a 20-term Taylor
    series) with numpy's products: nothing to compile.

    Parameters
    ----------
    M : array_like, shape (n, n)
        A real square matrix.

    Examples
    --------
    >>> E = expm_taylor([[0.0, 1.0], [-1.0, 0.0]])            # a rotation by 1 rad
    >>> bool(np.allclose(E, [[np.cos(1), np.sin(1)], [-np.sin(1), np.cos(1)]], atol=1e-15))
    True
    """
    M = np.asarray(M, dtype=float)
    n = M.shape[0]
    P = M.copy()
    alpha = 0.0
    for p in range(2, 7):
        P = P @ M
        if p >= 5:
            alpha = max(alpha, float(np.max(np.sum(np.abs(P), axis=0))) ** (1.0 / p))
    alpha = min(alpha, float(np.max(np.sum(np.abs(M), axis=0))) if n else 0.0)
    sq = 0
    while alpha > 0.5:
        alpha *= 0.5
        sq += 1
    A = M / 2.0**sq
    E = np.eye(n)
    T = np.eye(n)
    for kk in range(1, 21):
        T = (T @ A) / kk
        E = E + T
    for _ in range(sq):
        E = E @ E
    return E


def held_rest(A: NDArray[np.float64], B: NDArray[np.float64], C: NDArray[np.float64],
              period: float, phi: float,
              expm: Callable[[NDArray[np.float64]], NDArray[np.float64]] = expm_taylor
              ) -> Matrices:
    """``(Phi, Gamma_a, Gamma_b, C)`` of a realisation ``A, B, C`` held with the fraction
    `phi` of a sample of delay.

    Parameters
    ----------
    A, B, C : ndarray
        The realisation (``B`` a column, ``C`` a row).
    period : float
        ``T`` [s].
    phi : float
        The delay's fraction of a sample, ``0 <= phi < 1``.
    expm : callable
        The matrix exponential.

    Examples
    --------
    >>> Phi, ga, gb, C = held_rest(np.array([[-1.0]]), np.array([[1.0]]), np.array([[1.0]]),
    ...                            0.1, 0.0)                  # 1 / (s + 1)
    >>> round(float(Phi[0, 0]), 6), float(ga[0]), round(float(gb[0]), 6)   # 1 - exp(-0.1)
    (0.904837, 0.0, 0.095163)
    """
    n = A.shape[0]

    def integral(tau):  # exp(A tau) and int_0^tau exp(A s) ds B
        M = np.zeros((n + 1, n + 1))
        M[:n, :n], M[:n, n:] = A * tau, B * tau
        E = expm(M)
        return E[:n, :n], E[:n, n]

    Phi, _ = integral(period)
    Eb, gb = integral((1.0 - phi) * period)
    _, ga = integral(phi * period)
    return Phi, Eb @ ga, gb, C[0]


def held_state_space(a2: float, a1: float, rest: Matrices | None, period: float,
                     phi: float) -> Matrices:
    """``(Phi, Gamma_a, Gamma_b, C)`` of the whole plant: its rigid-body part
    ``a2 / s^2 + a1 / s`` held in closed form (its states first), then `rest`
    (:func:`held_rest`, None: none).

    Parameters
    ----------
    a2, a1 : float
        The rigid-body part (:func:`rigid_split`).
    rest : tuple or None
        The rest's matrices.
    period : float
        ``T`` [s].
    phi : float
        The delay's fraction of a sample.

    Examples
    --------
    >>> Phi, ga, gb, C = held_state_space(0.0, 1.0, None, 0.1, 0.25)    # 1 / s
    >>> Phi.tolist(), ga.tolist(), gb.tolist(), C.tolist()
    ([[1.0]], [0.025], [0.075], [1.0])
    """
    T = period
    tb = (1.0 - phi) * T
    blocks = []
    if a2 or a1:
        rigid = (np.array([[1.0, T], [0.0, 1.0]]),
                 np.array([(phi * T) ** 2 / 2.0 + tb * phi * T, phi * T]),
                 np.array([tb**2 / 2.0, tb]), np.array([a2, a1]))
        if not a2:  # 1 / s alone: the velocity state
            rigid = tuple(np.atleast_2d(x[1:, 1:]) if x.ndim == 2 else x[1:] for x in rigid)
        blocks.append(rigid)
    if rest is not None:
        blocks.append(rest)
    n = sum(b[0].shape[0] for b in blocks)
    Phi, ga, gb, C = np.zeros((n, n)), np.zeros(n), np.zeros(n), np.zeros(n)
    i = 0
    for P, a, b, c in blocks:
        k = P.shape[0]
        Phi[i:i + k, i:i + k], ga[i:i + k], gb[i:i + k], C[i:i + k] = P, a, b, c
        i += k
    return Phi, ga, gb, C


def zoh_state_space(num: ArrayLike, den: ArrayLike, period: float,
                    delay_samples: float = 0.0) -> tuple[int, Matrices]:
    """The strictly proper plant ``num / den`` behind a zero-order hold `delay_samples` late:
    the whole samples of delay ``D`` and ``(Phi, Gamma_a, Gamma_b, C)`` (see the module).

    Parameters
    ----------
    num, den : array_like
        The plant, highest power first (at most two poles at ``s = 0``).
    period : float
        ``T`` [s].
    delay_samples : float
        ``d >= 0``.

    Raises
    ------
    ValueError
        A plant that is not strictly proper or has more than two integrators.

    Examples
    --------
    >>> whole, (Phi, ga, gb, C) = zoh_state_space([1.0], [1.0, 0.0], 0.1, 0.25)   # 1 / s
    >>> whole, Phi.tolist(), ga.tolist(), gb.tolist()
    (0, [[1.0]], [0.025], [0.075])
    """
    if np.trim_zeros(np.asarray(num, float), "f").size >= \
            np.trim_zeros(np.asarray(den, float), "f").size:
        raise ValueError("the plant behind the hold must be strictly proper")
    whole = math.floor(delay_samples)
    phi = delay_samples - whole
    a2, a1, rest_num, rest_den = rigid_split(num, den)
    rest = None
    if np.any(rest_num != 0.0):
        A, B, C, _ = canonical_state_space(rest_num, rest_den)
        rest = held_rest(A, B, C, float(period), phi)
    return whole, held_state_space(a2, a1, rest, float(period), phi)
