"""The open loop of a plant with a Bouc-Wen link: fourth-order Runge-Kutta with sensitivities.

Every Bouc-Wen parameter set (:class:`~motionhyst.hysteresis.BoucWen`'s
normalised form mapped exactly onto the general one
``z' = alpha y' - beta (gamma |y'| |z|^(nu-1) z + delta y' |z|^nu)``,
:func:`bouc_wen_general`) and the linear stage: classical fourth-order
Runge-Kutta on ``(q, q', z)`` of ``M q'' + C q' + K q = e (u - z)``, one compiled
integrator for every plant (compiled for the plant's size), with the forward
sensitivities of the output to the plant's parameters (``m, c, k`` or
``m1, m2, b, k``) and ``alpha, beta*gamma, beta*delta, nu`` when asked: what
:mod:`motionhyst.identify.input_output` fits the Bouc-Wen benchmark with.
The other links run on the time engine (:mod:`motionhyst.time.engine`);
this integrator stays its own because the benchmark's identification is
defined by its numbers (fourth order in the step, with exact sensitivities
of the Bouc-Wen state, which the element update has no partials for).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.compiled import njit
from motionhyst.hysteresis import BoucWen
from motionhyst.plants.mass_spring_damper import MassSpringDamper
from motionhyst.time.periodic_runs import (
    PeriodExtrapolation,
    max_periods,
    periodic_output,
    whole_periods,
)
from motionhyst.time.resample import fine_blocks, fine_input

if TYPE_CHECKING:
    from motionhyst.plants.two_mass import TwoMassStage

    Plant = MassSpringDamper | TwoMassStage

__all__ = ["BW_PARAMETERS", "bouc_wen_general", "simulate_bouc_wen"]

#: Names of the general Bouc-Wen parameters the compiled integrator carries (sensitivity order).
BW_PARAMETERS = ("m", "c", "k", "alpha", "beta_gamma", "beta_delta", "nu")


def bouc_wen_general(link: BoucWen) -> tuple[float, float, float, float]:
    """``(alpha, beta*gamma, beta*delta, nu)`` of a Bouc-Wen link in the general form.

    The normalised form ``(k, fc, n, beta_n, gamma_n)`` maps exactly onto
    ``alpha = k``, ``beta*gamma = k beta_n / fc^n``, ``beta*delta = k gamma_n / fc^n``,
    ``nu = n`` (:attr:`BoucWen.general`; the force is the general form's ``z``).

    Parameters
    ----------
    link : BoucWen
        The link.

    Returns
    -------
    tuple of float

    Examples
    --------
    >>> from motionhyst.hysteresis import BoucWen
    >>> bouc_wen_general(BoucWen(k=5e4, fc=20.0, n=1.0, beta=0.6, gamma=0.2))
    (50000.0, 1500.0, 500.0, 1.0)
    """
    g = link.general
    return (float(g["alpha"]), float(g["beta"] * g["gamma"]), float(g["beta"] * g["delta"]),
            float(g["nu"]))


@njit(cache=True, inline="always")
def _rate(v, z, alpha, bg, bd, nu, sens):  # pragma: no cover - compiled
    """``z'`` and its partial derivatives in v, z and nu."""
    az = abs(z)
    if nu == 1.0:
        pn1 = 1.0
        pn = az
    else:
        pn1 = az ** (nu - 1.0) if az > 0.0 else 0.0
        pn = pn1 * az
    av = abs(v)
    sv = 1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0)
    sz = 1.0 if z > 0.0 else (-1.0 if z < 0.0 else 0.0)
    g = av * pn1 * z      # |v| |z|^(nu-1) z
    d = v * pn            # v |z|^nu
    f = alpha * v - bg * g - bd * d
    f_v = alpha - bg * sv * pn1 * z - bd * pn
    f_z = -nu * pn1 * (bg * av + bd * v * sz)
    f_nu = 0.0
    if sens is not None and az > 0.0:
        f_nu = -(bg * g + bd * d) * math.log(az)
    return f, f_v, f_z, f_nu, g, d


@njit(cache=True, inline="always")
def _deriv(uu, x, s, mass, C, K, dmass, dC, dK, li, lp, acc, dx, ds, sens
           ):  # pragma: no cover - compiled
    """Rates of the state ``(q, q', z)`` of ``M q'' + C q' + K q = e_li (u - z)`` and of
    its sensitivities (columns: the plant's parameters, then alpha, beta*gamma,
    beta*delta, nu; ``lp`` holds those four)."""
    n = len(mass)
    z = x[2 * n]
    for i in range(n):
        f = uu if i == li else 0.0
        for j in range(n):
            f -= C[i, j] * x[n + j]
        for j in range(n):
            f -= K[i, j] * x[j]
        if i == li:
            f -= z
        acc[i] = f / mass[i]
    rf, f_v, f_z, f_nu, g, d = _rate(x[n + li], z, lp[0], lp[1], lp[2], lp[3], sens)
    for i in range(n):
        dx[i] = x[n + i]
        dx[n + i] = acc[i]
    dx[2 * n] = rf
    if sens is not None:
        n_plant = len(dmass)
        nc = len(dmass) + 4
        for i in range(n):
            for col in range(nc):
                ds[i, col] = s[n + i, col]
            for col in range(nc):
                ds[n + i, col] = 0.0
            for j in range(n):
                cij = C[i, j]
                for col in range(nc):
                    ds[n + i, col] -= cij * s[n + j, col]
            for j in range(n):
                kij = K[i, j]
                for col in range(nc):
                    ds[n + i, col] -= kij * s[j, col]
            if i == li:
                for col in range(nc):
                    ds[n + i, col] -= s[2 * n, col]
            mi = mass[i]
            for col in range(nc):
                ds[n + i, col] = ds[n + i, col] / mi
        for col in range(nc):
            ds[2 * n, col] = f_v * s[n + li, col] + f_z * s[2 * n, col]
        for col in range(n_plant):
            for i in range(n):
                t = dmass[col][i] * acc[i]
                for j in range(n):
                    t += dC[col, i, j] * x[n + j]
                for j in range(n):
                    t += dK[col, i, j] * x[j]
                ds[n + i, col] -= t / mass[i]
        ds[2 * n, n_plant] += x[n + li]
        ds[2 * n, n_plant + 1] -= g
        ds[2 * n, n_plant + 2] -= d
        ds[2 * n, n_plant + 3] += f_nu


@njit(cache=True, nogil=True)
def _rk4_run(uf, h, r, mass, C, K, dmass, dC, dK, li, lo, lp, x0, s0, sens
             ):  # pragma: no cover - compiled
    """RK4 with step `h` over ``uf`` (input at half steps); outputs every `r` steps.

    Returns the output ``q[lo]`` and its sensitivities at the record samples
    (the first at the initial state) and the final state and sensitivities
    (``sens``: True, or None for none).  ``mass`` (the diagonal of ``M``) and
    ``dmass`` are tuples, so that the run is compiled for the plant's size.
    """
    n_steps = (uf.shape[0] - 1) // 2
    n_out = n_steps // r + 1
    ns = 2 * len(mass) + 1
    nc = len(dmass) + 4
    y = np.empty(n_out)
    sy = np.zeros((n_out, nc))
    x = x0.copy()
    s = s0.copy()
    acc = np.empty(len(mass))
    k1 = np.empty(ns)
    k2 = np.empty(ns)
    k3 = np.empty(ns)
    k4 = np.empty(ns)
    q1 = np.zeros((ns, nc))
    q2 = np.zeros((ns, nc))
    q3 = np.zeros((ns, nc))
    q4 = np.zeros((ns, nc))
    xt = np.empty(ns)
    st = np.zeros((ns, nc))
    y[0] = x[lo]
    if sens is not None:
        for j in range(nc):
            sy[0, j] = s[lo, j]
    for i in range(n_steps):
        _deriv(uf[2 * i], x, s, mass, C, K, dmass, dC, dK, li, lp, acc, k1, q1, sens)
        for a in range(ns):
            xt[a] = x[a] + 0.5 * h * k1[a]
        if sens is not None:
            for a in range(ns):
                for j in range(nc):
                    st[a, j] = s[a, j] + 0.5 * h * q1[a, j]
        _deriv(uf[2 * i + 1], xt, st, mass, C, K, dmass, dC, dK, li, lp, acc, k2, q2, sens)
        for a in range(ns):
            xt[a] = x[a] + 0.5 * h * k2[a]
        if sens is not None:
            for a in range(ns):
                for j in range(nc):
                    st[a, j] = s[a, j] + 0.5 * h * q2[a, j]
        _deriv(uf[2 * i + 1], xt, st, mass, C, K, dmass, dC, dK, li, lp, acc, k3, q3, sens)
        for a in range(ns):
            xt[a] = x[a] + h * k3[a]
        if sens is not None:
            for a in range(ns):
                for j in range(nc):
                    st[a, j] = s[a, j] + h * q3[a, j]
        _deriv(uf[2 * i + 2], xt, st, mass, C, K, dmass, dC, dK, li, lp, acc, k4, q4, sens)
        for a in range(ns):
            x[a] += h / 6.0 * (k1[a] + 2.0 * k2[a] + 2.0 * k3[a] + k4[a])
        if sens is not None:
            for a in range(ns):
                for j in range(nc):
                    s[a, j] += h / 6.0 * (q1[a, j] + 2.0 * q2[a, j] + 2.0 * q3[a, j] + q4[a, j])
        if (i + 1) % r == 0:
            o = (i + 1) // r
            y[o] = x[lo]
            if sens is not None:
                for j in range(nc):
                    sy[o, j] = s[lo, j]
    return y, sy, x, s


def simulate_bouc_wen(p: NDArray[np.float64], u: NDArray[np.float64], fs: float, r: int, *,
                      periodic: bool, sensitivities: bool, upsampled: NDArray | None = None,
                      plant: Plant | None = None
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Output of a plant with a general Bouc-Wen link and its sensitivities (RK4).

    Parameters
    ----------
    p : ndarray
        The plant's parameters (:attr:`MassSpringDamper.PARAMETERS`,
        :attr:`TwoMass.PARAMETERS`), then ``alpha, beta*gamma, beta*delta, nu``
        (for the mass-spring-damper: :data:`BW_PARAMETERS`).
    u : ndarray
        Force record at `fs` [N].
    fs : float
        Record sampling frequency [Hz].
    r : int
        RK4 steps per sample.
    periodic : bool
        From rest (False) or the periodic steady state of the period `u` (True;
        with zero mean for a floating plant, as :meth:`OpenLoop.simulate`).
    sensitivities : bool
        Also return ``dy/dp`` (else an empty array).
    upsampled : ndarray, optional
        ``fine_input(u, 2 r, periodic)``, if already computed (it depends on `u` only).
    plant : MassSpringDamper or TwoMass, optional
        The kind of plant (and its output) the first entries of `p` are the
        parameters of; its own values are not used.  Default: a mass-spring-damper.

    Returns
    -------
    y : ndarray
        Output position at the record samples [m].
    dy_dp : ndarray, shape ``(len(u), len(p))``
        Its derivatives in ``p``.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.time.openloop import TwoMass
    >>> u = 30 * np.sin(2 * np.pi * 5 * np.arange(300) / 750)
    >>> p = np.array([2.0, 3.0, 20.0, 2e5, 5e4, 800.0, -1100.0, 1.0])
    >>> y, dy = simulate_bouc_wen(p, u, 750.0, 20, periodic=False, sensitivities=True,
    ...                           plant=TwoMass(1.0, 1.0, 0.0, 1.0))
    >>> y.shape, dy.shape
    ((300,), (300, 8))
    """
    n = whole_periods(u) if periodic else 1
    if n > 1:  # the steady state of one period, repeated
        y, sy = simulate_bouc_wen(p, u[: u.size // n], fs, r, periodic=True,
                                  sensitivities=sensitivities, plant=plant)
        return np.tile(y, n), np.tile(sy, (n, 1))
    structure = plant if plant is not None else MassSpringDamper(1.0, 0.0, 0.0)
    n_plant = len(structure.PARAMETERS)
    p = np.ascontiguousarray(p, dtype=float)
    if p.size != n_plant + 4:
        raise ValueError(f"expected {n_plant + 4} parameters, got {p.size}")
    mech = structure.mechanics(p[:n_plant])
    lp = np.ascontiguousarray(p[n_plant:])
    h = 1.0 / (fs * r)
    ns = 2 * mech.n + 1
    x0 = np.zeros(ns)
    s0 = np.zeros((ns, p.size))

    def run(x0, s0, uf):
        # the masses and parameter count as tuples: compiled for their sizes (unrolled loops);
        # no sensitivities: None, which removes their code from the compiled run; `uf` with
        # the plant's constant force offset added
        return _rk4_run(uf, h, r, tuple(mech.mass), mech.C, mech.K,
                        tuple(tuple(row) for row in mech.dmass), mech.dC, mech.dK, mech.link,
                        mech.output, lp, x0, s0, True if sensitivities else None)

    if not periodic:  # through the record's fine input block by block, the state carried on
        y, sy = np.empty(u.size), np.empty((u.size, p.size if sensitivities else 0))
        k = 0
        for uf in [upsampled] if upsampled is not None else fine_blocks(u, 2 * r):
            yb, syb, x0, s0 = run(x0, s0, uf + mech.force_offset if mech.force_offset else uf)
            first = 0 if k == 0 else 1  # a block's first output is the previous one's last
            y[k:k + yb.size - first] = yb[first:]
            if sensitivities:
                sy[k:k + yb.size - first] = syb[first:]
            k += yb.size - first
        return y, sy
    uf = upsampled if upsampled is not None else fine_input(u, 2 * r, periodic)
    if mech.force_offset:  # the plant's constant force offset adds to the force, once
        uf = uf + mech.force_offset
    if isinstance(structure, MassSpringDamper):  # as ever: a negative c or k taken as 0
        mech_tau = structure.mechanics([p[0], max(p[1], 0.0), max(p[2], 0.0)])
    else:
        mech_tau = mech
    if mech.floating and lp[0] > 0.0:
        # the lightly damped mode of the stage on its link would take long to forget a start
        # from rest: start from the steady state with the link a spring alpha
        x0[:-1] = mech.linear_periodic_state(u, fs, lp[0])
        x0[-1] = lp[0] * x0[mech.link]
    state = [x0, s0]
    extrapolate = PeriodExtrapolation(weighted=(0,))  # the sensitivities follow the state

    def next_period():
        y, sy, state[0], state[1] = run(*state, uf)
        finite = bool(np.all(np.isfinite(state[0])))
        jump = extrapolate(state) if finite else None
        if jump is not None:
            state[:] = jump
        return y, sy, finite

    return periodic_output(next_period, max_periods(mech_tau, lp[0], u.size / fs),
                            mech.floating, bool(sensitivities))
