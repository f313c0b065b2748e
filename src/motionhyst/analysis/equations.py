"""The paper's closed-form expressions of the quasi-linear loop, eqs. (12)-(21).

Each takes frequency responses (or the stage's numbers) and returns the
expression as the paper writes it: the quasi-linear plant ``P^phi`` (eq. 12),
the sensitivity ``S1^phi`` (eq. 15), the feedforward mismatch ``E`` (eq. 18),
its low-frequency asymptote (eq. 20) and the characteristic frequencies ``f*``
(eq. 13) and of eq. (21).  :mod:`motionhyst.analysis.quasilinear` evaluates them
on a loop; :mod:`motionhyst.analysis.plausibility` uses ``f*``.

Examples
--------
>>> from motionhyst.analysis.equations import f_star
>>> round(f_star(20.0, 22.5), 4)                           # Table I: k = 20 N/m, M = 22.5 kg
0.1501
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.lti import TWO_PI

__all__ = ["f_star", "mismatch", "mismatch_asymptote", "mismatch_crossover",
           "over_error_without_link", "quasi_linear_plant", "sensitivity_s1"]


def quasi_linear_plant(P1: ArrayLike, P2: ArrayLike, D: ArrayLike) -> NDArray[np.complex128]:
    """Quasi-linear plant ``P^phi = P2 / (1 + D P1)`` from ``u`` to ``y2``, paper eq. (12).

    Parameters
    ----------
    P1 : array_like
        Frequency response from ``u - w`` to ``y1`` [m/N].
    P2 : array_like
        Frequency response from ``u`` to ``y2`` [m/N].
    D : array_like
        Describing function of the link [N/m].

    Examples
    --------
    >>> complex(quasi_linear_plant(-1e-3, -2e-3, 0.0))    # no link: P2
    (-0.002+0j)
    >>> round(abs(complex(quasi_linear_plant(-1e-3, -2e-3, 20.0))), 6)
    0.002041
    """
    return np.asarray(P2) / (1.0 + np.asarray(D) * np.asarray(P1))


def sensitivity_s1(P1: ArrayLike, D: ArrayLike) -> NDArray[np.complex128]:
    """Sensitivity ``S1^phi = (1 + D P1)^-1`` from ``u`` to ``u - w``, paper eq. (15).

    Parameters
    ----------
    P1 : array_like
        Frequency response from ``u - w`` to ``y1`` [m/N].
    D : array_like
        Describing function of the link [N/m].

    Examples
    --------
    >>> round(complex(sensitivity_s1(-1e-3, 20.0)).real, 4)
    1.0204
    """
    return 1.0 / (1.0 + np.asarray(D) * np.asarray(P1))


def mismatch(C: ArrayLike, P1: ArrayLike, P2: ArrayLike, Pr: ArrayLike, Pf2: ArrayLike,
             D: ArrayLike) -> NDArray[np.complex128]:
    """Feedforward mismatch ``E = e / e_hat`` due to hysteresis, paper eq. (18).

    ``E = (C P2 + 1)(Pr - P2 S1) / (Pf2 (C P2 S1 + 1))``: the quasi-linear
    tracking error with the dynamic link over the error without it, both with
    the rigid-body feedforward ``Pr^-1``.  ``Pr - P2 S1`` is evaluated as
    ``Pf2 + P2 D P1 S1``, which avoids the cancellation of ``Pr`` and ``P2`` at
    low frequency.

    Parameters
    ----------
    C, P1, P2, Pr, Pf2 : array_like
        Frequency responses of the controller and the plant's parts (eqs. 1-2).
    D : array_like
        Describing function of the hysteresis [N/m].

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst import default_scenario
    >>> from motionhyst.core.lti import freqresp
    >>> loop, w = default_scenario().loop(), 2 * np.pi * 5.0     # Table I at 5 Hz, 10 mm
    >>> C, P1, P2, Pf2 = (freqresp(s, w) for s in (loop.controller, loop.P1, loop.P2,
    ...                                            loop.plant.Pf2))
    >>> Pr, D = 1 / (loop.M * (1j * w) ** 2), loop.hysteresis.describing_function(0.01)
    >>> np.abs(mismatch(C, P1, P2, Pr, Pf2, D)).round(2).tolist()   # as analyze() gives it
    [6.04]
    """
    C, P1, P2, Pr, Pf2, D = (np.asarray(x) for x in (C, P1, P2, Pr, Pf2, D))
    S1 = sensitivity_s1(P1, D)
    return over_error_without_link((C * P2 + 1.0) * (Pf2 + P2 * D * P1 * S1),
                                   Pf2 * (C * P2 * S1 + 1.0))


def over_error_without_link(e: ArrayLike, e_hat: ArrayLike) -> NDArray[np.complex128]:
    """``e / e_hat``, the quotient of a mismatch (eqs. 18, 20), nan where ``e_hat = 0``.

    With a rigid plant (``Pf2 = Pr - P2 = 0``: a mass-damper with ``c = 0``) the
    rigid-body feedforward ``M r''`` leaves no error without the link, so the mismatch
    compares the link's error with nothing: it is not defined (nan, never ``inf`` and
    numpy's division warning).

    Parameters
    ----------
    e : array_like
        The error with the link (or a quantity proportional to it).
    e_hat : array_like
        The error without it, in the same proportion.

    Examples
    --------
    >>> over_error_without_link([2.0, 1.0], [4.0, 0.0]).tolist()
    [(0.5+0j), (nan+nanj)]
    """
    e, e_hat = np.asarray(e, dtype=complex), np.asarray(e_hat, dtype=complex)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(e_hat == 0, complex(np.nan, np.nan), e / np.where(e_hat == 0, 1, e_hat))


def mismatch_asymptote(Pr: ArrayLike, Pf2: ArrayLike, D: ArrayLike) -> NDArray[np.complex128]:
    """Low-frequency asymptote ``E~ = Pr^2 D / Pf2`` of the mismatch, paper eq. (20).

    Parameters
    ----------
    Pr : array_like
        Rigid-body plant ``1 / (M s^2)`` [m/N].
    Pf2 : array_like
        The flexible part ``Pr - P2`` [m/N].
    D : array_like
        Describing function of the link [N/m].

    Examples
    --------
    Table I's stage and link at 5 Hz and 10 mm (where eq. (18) gives ``|E| = 6.04``):

    >>> import numpy as np
    >>> from motionhyst import Jenkins, TwoMassStage
    >>> from motionhyst.core.lti import freqresp
    >>> stage, w = TwoMassStage(5.0, 17.5, 90.0, 7.4e7), 2 * np.pi * 5.0
    >>> Pr, Pf2 = 1 / (stage.M * (1j * w) ** 2), freqresp(stage.Pf2, w)
    >>> D = Jenkins(k=20.0, fc=0.05).describing_function(0.01)
    >>> np.abs(mismatch_asymptote(Pr, Pf2, D)).round(2).tolist()
    [5.36]
    """
    return over_error_without_link(np.asarray(Pr) ** 2 * np.asarray(D), Pf2)


def f_star(k: float, M: float) -> float:
    """Frequency above which ``P^phi`` tends to ``P2``, ``sqrt(k/M) / (2 pi)`` [Hz], eq. (13).

    Parameters
    ----------
    k : float
        Initial stiffness of the link [N/m].
    M : float
        Total mass of the stage [kg].

    Examples
    --------
    >>> round(f_star(20.0, 22.5), 4)                         # Table I: k = 20 N/m, M = 22.5 kg
    0.1501
    """
    return float(np.sqrt(k / M) / TWO_PI)


def mismatch_crossover(k: float, m1: float, m2: float, D_abs: float) -> float:
    """Crossover ``|E~| = 1`` of the asymptote, ``(k |D| / (m1 m2))^(1/4) / (2 pi)`` [Hz], eq. (21).

    `k` is the stage's internal stiffness, not the link's.

    Parameters
    ----------
    k : float
        The stage's internal stiffness [N/m].
    m1 : float
        Actuated mass [kg].
    m2 : float
        Mass at the point of control [kg].
    D_abs : float
        ``|D|`` of the link at the reference amplitude [N/m].

    Examples
    --------
    >>> round(mismatch_crossover(7.4e7, 5.0, 17.5, 6.171), 2)  # Table I at 10 mm; the paper: 7.6 Hz
    7.61
    """
    return float((k * D_abs / (m1 * m2)) ** 0.25 / TWO_PI)
