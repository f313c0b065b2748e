"""Two-degree-of-freedom discrete controllers: ``u = R(z) r - Y(z) y``, and the cascade.

A controller that acts on the reference and the measured output separately
cannot be written as ``C (r - y)``; the industrial standard is a position
loop around a velocity loop, the velocity taken from the measured position.
The EMPS benchmark's (Janot, Gautier, Brunot 2019), at ``F = 1 / T``::

    u_k = g kv (kp (r_k - y_k) - (y_k - y_{k-1}) F)

is ``R = g kv kp`` and ``Y = g kv ((kp + F) - F z^-1)``
(:func:`position_velocity_cascade`); any other is given by its four
polynomials in ascending powers of ``z^-1`` (:func:`two_dof_z`).

Examples
--------
>>> from motionhyst.controllers.two_dof import position_velocity_cascade
>>> c = position_velocity_cascade(kp=160.18, kv=243.45, gain=35.15065, sample_rate_hz=1000.0)
>>> [round(float(x), 1) for x in c.y_num]              # g kv (kp + F), -g kv F
[9928154.2, -8557425.7]
"""

from __future__ import annotations

from numpy.typing import ArrayLike

from motionhyst.controllers.sampled import SampledController

__all__ = ["position_velocity_cascade", "two_dof_z"]


def two_dof_z(r_num: ArrayLike, r_den: ArrayLike, y_num: ArrayLike, y_den: ArrayLike,
              sample_rate_hz: float, delay_samples: float = 0.0,
              u_max: float | None = None) -> SampledController:
    """``u_k = R(z) r_k - Y(z) y_k`` from its polynomials in ascending powers of ``z^-1``.

    Parameters
    ----------
    r_num, r_den : array_like
        Reference path ``R(z)``.
    y_num, y_den : array_like
        Feedback path ``Y(z)``.
    sample_rate_hz : float
        ``1 / T`` [Hz].
    delay_samples : float
        Delay of the output [samples].
    u_max : float, optional
        Output limit [N].

    Returns
    -------
    SampledController

    Examples
    --------
    >>> from motionhyst.controllers.two_dof import two_dof_z
    >>> c = two_dof_z([2.0], [1.0], [3.0, -1.0], [1.0], 100.0)
    >>> c.one_dof, c.dc_gain()                             # Y(1) = 3 - 1
    (False, 2.0)
    """
    return SampledController(r_num, r_den, y_num, y_den, sample_rate_hz=sample_rate_hz,
                             delay_samples=delay_samples, u_max=u_max)


def position_velocity_cascade(kp: float, kv: float, gain: float, sample_rate_hz: float,
                              delay_samples: float = 0.0, u_max: float | None = None
                              ) -> SampledController:
    """``u = gain kv (kp (r - y) - y')``, ``y'`` the two-sample difference of the measured ``y``.

    Parameters
    ----------
    kp : float
        Position gain [1/s].
    kv : float
        Velocity gain [V s/m or N s/m].
    gain : float
        Drive gain from the velocity loop's output to force [N/V] (1 when ``kv`` is in N s/m).
    sample_rate_hz : float
        ``F = 1 / T`` [Hz].
    delay_samples : float
        Delay of the output [samples].
    u_max : float, optional
        Force limit [N] (the drive's saturation times `gain`).

    Returns
    -------
    SampledController

    Examples
    --------
    >>> from motionhyst.controllers.two_dof import position_velocity_cascade
    >>> c = position_velocity_cascade(2.0, 3.0, 1.0, 10.0)
    >>> c.r_num.tolist(), c.y_num.tolist()                 # R = 6, Y = 3 ((2 + 10) - 10 z^-1)
    ([6.0], [36.0, -30.0])
    """
    g = float(gain) * float(kv)
    F = float(sample_rate_hz)
    return SampledController([g * kp], [1.0], [g * (kp + F), -g * F], [1.0],
                             sample_rate_hz=F, delay_samples=delay_samples, u_max=u_max)
