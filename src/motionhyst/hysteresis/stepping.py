"""The compiled time step of a link's elements, shared by every time-domain path.

A link model states how it is stepped (:meth:`Hysteresis.time_stepping`) as a
:class:`Stepping`: one row per element, each a primitive kind of this module
(``STOP``, ``DAHL``, ``BOUC_WEN``, ``LUGRE``, ``MAXWELL``, ``COULOMB``) with its
parameters; ``VISCOUS``, a damper by direction, is no link's own element but a plant's
viscous friction that depends on the direction (:meth:`Stepping.with_viscous`).  The time
simulation and the open-loop force of a feedforward model advance the rows
with :func:`advance`, so they never need to know which model they run;
:func:`advance_partials` differentiates the step of the kinds in
:data:`DIFFERENTIATED` (the open loop's sensitivities for identification).

Examples
--------
>>> import numpy as np
>>> from motionhyst.hysteresis import Jenkins
>>> st = Jenkins(k=1e4, fc=5.0).time_stepping()
>>> w = open_loop(st.codes, st.params, st.state0, np.array([0.0, 1e-4, 1e-3, 0.0]), 1e-3,
...               GL_T, GL_W)
>>> w.tolist()
[0.0, 1.0, 5.0, -5.0]
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.compiled import njit
from motionhyst.hysteresis._lugre_kernels import lugre_relax
from motionhyst.hysteresis._ode_kernels import GL_T, GL_W, bouc_wen_step, dahl_advance

__all__ = ["BOUC_WEN", "CALL_ELEMENT_STEPS", "COULOMB", "DAHL", "DIFFERENTIATED", "GL_T", "GL_W",
           "LUGRE", "MAXWELL", "N_PARAMS", "N_PARTIALS", "STOP", "VISCOUS", "Stepping", "advance",
           "advance_partials", "backward_weights", "coulomb_implicit", "open_loop",
           "open_loop_calls", "open_loop_chunk"]

STOP, DAHL, BOUC_WEN, LUGRE, MAXWELL, COULOMB, VISCOUS = 0, 1, 2, 3, 4, 5, 6
N_PARAMS = 6


@dataclass(frozen=True)
class Stepping:
    """How the compiled time step advances a link: one row per element.

    Attributes
    ----------
    codes : ndarray of int64, shape (n,)
        Primitive kind of each element (``STOP``, ``DAHL``, ``BOUC_WEN``, ``LUGRE``,
        ``MAXWELL``, ``COULOMB``, ``VISCOUS``).
    params : ndarray, shape (n, N_PARAMS)
        Each element's parameters, in the order :func:`advance` reads them.
    state0 : ndarray, shape (n,)
        States at rest.
    scale : float
        A force scale [N] of the link (its slip or saturation force), for tolerances.

    Examples
    --------
    >>> from motionhyst import MaxwellSlip
    >>> from motionhyst.hysteresis.stepping import STOP
    >>> s = MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]).time_stepping()
    >>> bool((s.codes == STOP).all()), s.scale                # two stop operators, total slip force
    (True, 0.04)
    """

    codes: NDArray[np.int64]
    params: NDArray[np.float64]
    state0: NDArray[np.float64]
    scale: float

    @classmethod
    def from_rows(cls, rows: list[tuple[int, tuple[float, ...]]], scale: float) -> Stepping:
        """From ``(code, parameters)`` rows, the elements at rest.

        Parameters
        ----------
        rows : list of (int, tuple of float)
            Element code and its parameters, one row per element.
        scale : float
            Force scale of the link [N] (its total slip force).
        """
        codes = np.array([c for c, _ in rows], dtype=np.int64)
        params = np.zeros((len(rows), N_PARAMS))
        for j, (_, p) in enumerate(rows):
            params[j, :len(p)] = p
        return cls(codes, params, np.zeros(len(rows)), float(scale))

    def state_bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The range of each element's state: ``(lo, hi)`` (infinite where it has none).

        A stop operator's force within its slip force, a rigid slider's within its
        slip forces, a Dahl element's normalised force within 1, LuGre's bristle
        deflection within ``max(fc, fs) / sigma0``.

        Examples
        --------
        >>> from motionhyst import MaxwellSlip
        >>> MaxwellSlip(k=[10.0, 6.0], fc=[0.01, 0.03]).time_stepping().state_bounds()[1]
        array([0.01, 0.03])
        """
        lo = np.full(self.codes.size, -np.inf)
        hi = np.full(self.codes.size, np.inf)
        for j, (code, p) in enumerate(zip(self.codes, self.params, strict=True)):
            if code == STOP:
                lo[j], hi[j] = -p[1], p[1]
            elif code == COULOMB:
                lo[j], hi[j] = -p[1], p[0]
            elif code == DAHL:
                lo[j], hi[j] = -1.0, 1.0
            elif code == LUGRE:
                hi[j] = max(p[3], p[4]) / p[0]
                lo[j] = -hi[j]
        return lo, hi

    @classmethod
    def empty(cls) -> Stepping:
        """No link: no elements, unit force scale."""
        return cls(np.zeros(0, np.int64), np.zeros((0, N_PARAMS)), np.zeros(0), 1.0)

    def with_viscous(self, c_pos: float, c_neg: float, keep_zero: bool = False) -> Stepping:
        """The rows with a viscous force by direction beside the link's: ``c_pos v`` moving
        forward, ``c_neg v`` backward (a plant's direction-dependent viscous friction on the
        link's coordinate; either may be negative, the plant's own damper holding the rest).

        A lone rigid slider (``COULOMB``, stepped in closed form) takes them into its own
        viscous terms; any other link gets a ``VISCOUS`` row after its own (the last row).

        Parameters
        ----------
        c_pos, c_neg : float
            Viscous friction added moving forward and backward [N s/m].
        keep_zero : bool
            Add the row even when both are 0 (its sensitivities wanted).

        Returns
        -------
        Stepping
            The same when both are 0 (unless `keep_zero`).

        Examples
        --------
        >>> from motionhyst.hysteresis import Coulomb, Jenkins
        >>> Jenkins(k=1e4, fc=5.0).time_stepping().with_viscous(30.0, -30.0).codes.tolist()
        [0, 6]
        >>> Coulomb(fc=5.0).time_stepping().with_viscous(30.0, -30.0).params[0, :4].tolist()
        [5.0, 5.0, 30.0, -30.0]
        """
        if c_pos == 0.0 and c_neg == 0.0 and not keep_zero:
            return self
        if self.codes.size == 1 and self.codes[0] == COULOMB:
            params = self.params.copy()
            params[0, 2] += c_pos
            params[0, 3] += c_neg
            return Stepping(self.codes, params, self.state0, self.scale)
        row = np.zeros((1, N_PARAMS))
        row[0, :2] = c_pos, c_neg
        return Stepping(np.append(self.codes, VISCOUS), np.vstack([self.params, row]),
                        np.append(self.state0, 0.0), self.scale)



@njit(cache=True)
def backward_weights(h, h_prev):  # pragma: no cover - compiled
    """Weights ``(a, b)`` of the second-order backward difference over two steps of lengths
    `h_prev` then `h`: a quantity's rate at the end of the second step is
    ``(a d - b d_prev) / h`` from its changes ``d_prev`` and ``d`` over them.

    The slope, at the end, of the parabola through the three samples:
    ``a = 1 + rho``, ``b = rho h / h_prev`` with ``rho = h / (h + h_prev)``; ``(1.5, 0.5)``
    for equal steps (to the bit).  The first-order ``(1, 0)`` when `h_prev` is not > 0.
    LuGre's step takes its rates so (:func:`advance`): the steps of a sampled loop's run
    change length where its computation delay splits a controller period, and the weights
    of equal steps misread that change (the paper's loop at 10 kHz, 1.05 samples late:
    e1 90 % off).

    Parameters
    ----------
    h : float
        The last step's length [s], > 0.
    h_prev : float
        The length of the step before it [s].

    Returns
    -------
    tuple of float
        ``(a, b)``.

    Examples
    --------
    >>> backward_weights(1e-4, 1e-4)
    (1.5, 0.5)
    >>> a, b = backward_weights(1.0, 2.0)      # x = t^2 at t = 0, 2, 3: its rate at 3 is 6
    >>> (a * (9.0 - 4.0) - b * (4.0 - 0.0)) / 1.0
    6.0
    """
    if not h_prev > 0.0:
        return 1.0, 0.0
    rho = h / (h + h_prev)
    return 1.0 + rho, rho * h / h_prev


@njit("(int64, float64[::1], float64, float64, float64, float64, float64, float64, boolean, "
      "float64[::1], float64[::1])")
def advance(code, p, s, s_prev, dx, dx_prev, h, h_prev, first, glt,
            glw):  # pragma: no cover - compiled
    """New state and force of one element after a displacement `dx` over a time `h`.

    ``code``/``p`` as built by :func:`_elements`; the displacement is taken as
    linear in time over the step (monotone for the rate-independent kinds).
    `s_prev` and `dx_prev` are the state and the displacement one step earlier, `h_prev`
    that step's length, used by LuGre only and ignored on the `first` step.
    """
    if code == STOP:  # p = (k, fc); state w: exact stop operator
        v = s + p[0] * dx
        if v > p[1]:
            v = p[1]
        elif v < -p[1]:
            v = -p[1]
        return v, v
    if code == DAHL:  # p = (k / fc, fc, alpha); state w / fc
        du = p[0] * dx
        if du > 0.0:
            s = dahl_advance(s, du, p[2])
        elif du < 0.0:
            s = -dahl_advance(-s, -du, p[2])
        return s, p[1] * s
    if code == BOUC_WEN:  # p = (k / fc, fc, n, beta + gamma, beta - gamma, hmax); state w / fc
        s = bouc_wen_step(s, p[0] * dx, p[2], p[3], p[4], p[5], glt, glw)
        return s, p[1] * s
    if code == COULOMB:  # p = (fc_pos, fc_neg, c_pos, c_neg): a rigid slider; state w
        # the rigid limit of a stop operator: moving, the slip force and the viscous force of
        # the step's mean velocity; not moving, the force it held (a time step that solves for
        # the stick force, as the open loop's does, sets the state itself)
        if dx > 0.0:
            v = p[0] + (p[2] * dx / h if h > 0.0 else 0.0)
        elif dx < 0.0:
            v = -p[1] + (p[3] * dx / h if h > 0.0 else 0.0)
        else:
            v = s
        return v, v
    if code == VISCOUS:  # p = (c_pos, c_neg): a damper by direction; state its force
        if h <= 0.0:
            return 0.0, 0.0
        v = (p[0] if dx > 0.0 else p[1]) * dx / h  # the step's mean velocity
        return v, v
    if code == MAXWELL:  # p = (kv, cv): a spring kv in series with a damper cv; state f
        # exact for dx linear in time: f+ = f e^-a + cv (dx / h) (1 - e^-a), a = h kv / cv,
        # written as kv dx (1 - e^-a) / a (a spring kv for h = 0)
        a = h * p[0] / p[1]
        if a > 0.0:
            s = s * np.exp(-a) - p[0] * dx * np.expm1(-a) / a
        else:
            s = s + p[0] * dx
        return s, s
    # LuGre, p = (sigma0, sigma1, sigma2, fc, fs, vs); state z.  As in lugre_response, z
    # relaxes exactly for the step's constant velocity (lugre_relax).  The rates in
    # the force are taken at the sample by the second-order backward difference over the
    # two steps' lengths (backward_weights; v = (3 dx - dx_prev) / (2 h) for equal ones)
    # and z' likewise from z: the step's mean velocity is half a step late (first order),
    # and z' from the state equation at the sample would amplify the error of z by h / tau
    # when the bristles relax within a step (tau = g / (sigma0 |v|) < h, stiff bristles).
    sigma0 = p[0]
    if h <= 0.0:
        return s, sigma0 * s
    z0 = s
    s = lugre_relax(s, dx, h, sigma0, p[3], p[4], p[5])
    if first:
        v = dx / h
        zdot = (s - z0) / h
    else:
        wa, wb = backward_weights(h, h_prev)
        v = (wa * dx - wb * dx_prev) / h
        zdot = (wa * (s - z0) - wb * (z0 - s_prev)) / h
    return s, sigma0 * s + p[1] * zdot + p[2] * v


@njit("UniTuple(float64, 2)(float64[::1], float64, float64)", nogil=True)
def coulomb_implicit(p, a, b):  # pragma: no cover - compiled
    """Force and end velocity of a lone rigid slider (``COULOMB``) over an implicit step.

    The velocity at the step's end is ``v = a - b w`` (``b > 0``: the plant's
    response to the link force ``w``).  The slider slides forward if it must,
    ``w = fc_pos + c_pos v`` with ``v > 0``, which happens if ``a > b fc_pos``;
    backward likewise; else it sticks: ``v = 0`` and ``w = a / b`` (within
    ``-fc_neg .. fc_pos``).  The rigid limit of the stop operator, sticking
    included, solved exactly with no iteration; a stuck stage stays at rest
    to rounding (a step that held only its position would let the velocity grow).

    Examples
    --------
    >>> p = np.array([2.0, 3.0, 0.0, 0.0, 0.0, 0.0])
    >>> coulomb_implicit(p, 1e-6, 1e-6)            # held: 1 N of the 2 N it can hold
    (1.0, 0.0)
    >>> w, v = coulomb_implicit(p, 5e-6, 1e-6)     # slides forward at 2 N
    >>> float(w), round(float(v) * 1e6, 12)
    (2.0, 3.0)
    """
    if a > b * p[0]:
        v = (a - b * p[0]) / (1.0 + b * p[2])
        return p[0] + p[2] * v, v
    if a < -b * p[1]:
        v = (a + b * p[1]) / (1.0 + b * p[3])
        return -p[1] + p[3] * v, v
    return a / b, 0.0


#: Element kinds :func:`advance_partials` differentiates (not ``BOUC_WEN``)
DIFFERENTIATED = (STOP, DAHL, LUGRE, MAXWELL, COULOMB, VISCOUS)
#: Length of :func:`advance_partials`' derivative vectors: in ``s, s_prev, dx, dx_prev``, then
#: the element's ``N_PARAMS`` parameters
N_PARTIALS = 4 + N_PARAMS


@njit(cache=True, inline="always")
def _dahl_partials(zeta, v, alpha):  # pragma: no cover - compiled
    """``dahl_advance(zeta, v, alpha)`` and its derivatives in zeta, v and alpha."""
    y = 1.0 - zeta
    if y <= 0.0:
        return zeta, 1.0, 0.0, 0.0
    if v == 0.0:
        return zeta, 1.0, y ** alpha, 0.0
    eps = alpha - 1.0
    if abs(eps) < 1e-8:  # alpha = 1 (the alpha-derivative's limit; the general one cancels)
        e = math.exp(-v)
        yn = y * e
        if eps == 0.0:
            return zeta - y * math.expm1(-v), e, yn, -yn * (0.5 * v * v - v * math.log(y))
        zn, dz, dv, _ = _dahl_general(zeta, y, v, eps)
        return zn, dz, dv, -yn * (0.5 * v * v - v * math.log(y))
    return _dahl_general(zeta, y, v, eps)


@njit(cache=True, inline="always")
def _dahl_general(zeta, y, v, eps):  # pragma: no cover - compiled
    """:func:`_dahl_partials` for ``alpha = 1 + eps`` != 1 and ``y = 1 - zeta > 0`` (the
    state formed as :func:`~motionhyst.hysteresis._ode_kernels.dahl_advance` forms it)."""
    ye = y ** eps
    arg = eps * v * ye
    if arg <= -1.0:
        return 1.0, 0.0, 0.0, 0.0
    a = 1.0 + arg
    lg = -math.log1p(arg) / eps
    fac = math.exp(lg)  # A^(-1/eps)
    yn = y * fac
    d_zeta = fac * (1.0 - arg / a)
    d_v = y * ye * fac / a
    dlog = math.log1p(arg) / (eps * eps) - v * ye * (1.0 + eps * math.log(y)) / (eps * a)
    return zeta - y * math.expm1(lg), d_zeta, d_v, -yn * dlog


@njit("(int64, float64[::1], float64, float64, float64, float64, float64, float64, boolean, "
      "float64[::1], float64[::1])")
def advance_partials(code, p, s, s_prev, dx, dx_prev, h, h_prev, first, ds, df
                     ):  # pragma: no cover - compiled
    """:func:`~motionhyst.hysteresis.stepping.advance` with its partial derivatives.

    Returns the new state and force as ``advance`` does, and fills `ds` and
    `df` (length :data:`N_PARTIALS`) with the derivatives of the state and the
    force in ``(s, s_prev, dx, dx_prev, p[0], ..., p[N_PARAMS - 1])``, for the
    kinds in :data:`DIFFERENTIATED`.  They are exact wherever the update is
    differentiable, i.e. almost everywhere: a stop operator that starts or
    stops slipping inside a step, a LuGre or Dahl element at an exact
    reversal, have one-sided derivatives there.

    Examples
    --------
    A stop operator ``k = 2e4 N/m, fc = 10 N`` at 4 N moved by 0.1 mm: it
    reaches 6 N, so the force grows with ``k`` at rate ``dx``:

    >>> import numpy as np
    >>> from motionhyst.hysteresis.stepping import GL_T, GL_W, STOP, advance
    >>> p = np.array([2e4, 10.0, 0.0, 0.0, 0.0, 0.0])
    >>> ds, df = np.zeros(10), np.zeros(10)
    >>> advance_partials(STOP, p, 4.0, 4.0, 1e-4, 0.0, 1e-4, 1e-4, False, ds, df)
    (6.0, 6.0)
    >>> float(df[0]), float(df[2]), float(df[4])     # d/ds, d/ddx, d/dk
    (1.0, 20000.0, 0.0001)
    >>> advance(STOP, p, 4.0, 4.0, 1e-4, 0.0, 1e-4, 1e-4, False, GL_T, GL_W)
    (6.0, 6.0)
    """
    for i in range(N_PARTIALS):
        ds[i] = 0.0
        df[i] = 0.0
    if code == STOP:
        v = s + p[0] * dx
        if v > p[1]:
            v = p[1]
            ds[5] = 1.0
        elif v < -p[1]:
            v = -p[1]
            ds[5] = -1.0
        else:
            ds[0] = 1.0
            ds[2] = p[0]
            ds[4] = dx
        for i in range(N_PARTIALS):
            df[i] = ds[i]
        return v, v
    if code == DAHL:  # p = (k / fc, fc, alpha); state w / fc
        du = p[0] * dx
        if du > 0.0:
            sn, dz, dv, da = _dahl_partials(s, du, p[2])
        elif du < 0.0:
            sn, dz, dv, da = _dahl_partials(-s, -du, p[2])
            sn = -sn
            da = -da
        else:
            sn, dz, dv, da = s, 1.0, (1.0 - abs(s)) ** p[2] if abs(s) < 1.0 else 0.0, 0.0
        ds[0] = dz
        ds[2] = dv * p[0]
        ds[4] = dv * dx
        ds[6] = da
        for i in range(N_PARTIALS):
            df[i] = p[1] * ds[i]
        df[5] = sn
        return sn, p[1] * sn
    if code == COULOMB:  # p = (fc_pos, fc_neg, c_pos, c_neg); state w (stuck: see advance)
        if dx > 0.0:
            v = p[0]
            df[4] = 1.0
            if h > 0.0:
                v += p[2] * dx / h
                df[2] = p[2] / h
                df[6] = dx / h
        elif dx < 0.0:
            v = -p[1]
            df[5] = -1.0
            if h > 0.0:
                v += p[3] * dx / h
                df[2] = p[3] / h
                df[7] = dx / h
        else:
            v = s
            df[0] = 1.0
        for i in range(N_PARTIALS):
            ds[i] = df[i]
        return v, v
    if code == VISCOUS:  # p = (c_pos, c_neg); state its force
        if h <= 0.0:
            return 0.0, 0.0
        j = 0 if dx > 0.0 else 1
        v = p[j] * dx / h
        df[2] = p[j] / h
        df[4 + j] = dx / h
        for i in range(N_PARTIALS):
            ds[i] = df[i]
        return v, v
    if code == MAXWELL:  # p = (kv, cv); state f
        a = h * p[0] / p[1]
        if a > 0.0:
            e = math.exp(-a)
            phi = -math.expm1(-a) / a
            dphi = (a * e + math.expm1(-a)) / (a * a)
            sn = s * np.exp(-a) - p[0] * dx * np.expm1(-a) / a  # as advance forms it
            d_a = -s * e + p[0] * dx * dphi
            ds[0] = e
            ds[2] = p[0] * phi
            ds[4] = dx * phi + d_a * h / p[1]
            ds[5] = -d_a * h * p[0] / (p[1] * p[1])
        else:
            sn = s + p[0] * dx
            ds[0] = 1.0
            ds[2] = p[0]
            ds[4] = dx
        for i in range(N_PARTIALS):
            df[i] = ds[i]
        return sn, sn
    # LuGre, p = (sigma0, sigma1, sigma2, fc, fs, vs); state z (see stepping.advance)
    sigma0, sigma1, sigma2, fc, fs, vs = p[0], p[1], p[2], p[3], p[4], p[5]
    if h <= 0.0:
        ds[0] = 1.0
        df[0] = sigma0
        df[4] = s
        return s, sigma0 * s
    z0 = s
    if dx == 0.0:
        sn = z0
        ds[0] = 1.0
        ds[2] = 1.0
    else:
        v = dx / h
        r = v / vs
        e = math.exp(-r * r)
        g = fc + (fs - fc) * e
        g_v = (fs - fc) * e * (-2.0 * r / vs)
        sg = 1.0 if dx > 0.0 else -1.0
        q = sg * g / sigma0
        ad = abs(dx)
        ex = math.exp(-sigma0 * ad / g)
        sn = q + (z0 - q) * ex
        d_g = sg / sigma0 * (1.0 - ex) + (z0 - q) * ex * sigma0 * ad / (g * g)
        ds[0] = ex
        ds[2] = (z0 - q) * ex * (-sigma0 * sg / g) + d_g * g_v / h
        ds[4] = -q / sigma0 * (1.0 - ex) - (z0 - q) * ex * ad / g
        ds[7] = d_g * (1.0 - e)
        ds[8] = d_g * e
        ds[9] = d_g * (fs - fc) * e * 2.0 * r * r / vs
    if first:
        vf = dx / h
        zdot = (sn - z0) / h
        c1 = sigma1 / h
        df[0] = sigma0 * ds[0] + c1 * (ds[0] - 1.0)
        df[2] = (sigma0 + c1) * ds[2] + sigma2 / h
    else:
        wa, wb = backward_weights(h, h_prev)
        vf = (wa * dx - wb * dx_prev) / h
        zdot = (wa * (sn - z0) - wb * (z0 - s_prev)) / h
        c1 = wa * sigma1 / h
        df[0] = sigma0 * ds[0] + c1 * ds[0] - (wa + wb) * sigma1 / h
        df[1] = wb * sigma1 / h
        df[2] = (sigma0 + c1) * ds[2] + wa * sigma2 / h
        df[3] = -wb * sigma2 / h
    df[4] = sn + (sigma0 + c1) * ds[4]
    df[5] = zdot
    df[6] = vf
    for i in range(7, 10):
        df[i] = (sigma0 + c1) * ds[i]
    return sn, sigma0 * sn + sigma1 * zdot + sigma2 * vf


@njit(cache=True)
def open_loop_chunk(codes, params, s, s_prev, scalars, x, h, i0, glt,
                     glw):  # pragma: no cover - compiled
    """:func:`open_loop` for samples from index `i0` on.

    ``s``, ``s_prev`` (element states now and one step earlier) and
    ``scalars = (x, dx)`` of the previous sample are read (for ``i0 > 0``) and
    updated, so that a run in chunks equals one run.
    """
    n_t = x.shape[0]
    w = np.empty(n_t)
    if i0 == 0:
        for j in range(codes.shape[0]):  # element-wise: a slice assigned an array compiles
            # numba's shape-mismatch error message (seconds of the first compilation)
            s_prev[j] = s[j]
        x_prev = x[0] if n_t else 0.0
        dx_prev = 0.0
    else:
        x_prev = scalars[0]
        dx_prev = scalars[1]
    for k in range(n_t):
        i = i0 + k
        dx = x[k] - x_prev if i > 0 else 0.0
        wt = 0.0
        for j in range(codes.shape[0]):
            sj, f = advance(codes[j], params[j], s[j], s_prev[j], dx, dx_prev,
                            h if i > 0 else 0.0, h, i == 1, glt, glw)
            s_prev[j] = s[j]
            s[j] = sj
            wt += f
        w[k] = wt
        dx_prev = dx
        x_prev = x[k]
    scalars[0] = x_prev
    scalars[1] = dx_prev
    return w


CALL_ELEMENT_STEPS = 300_000
"""Samples times elements of one call of :func:`open_loop_chunk` from :func:`open_loop_calls`
(0.03-0.2 s, by the elements' kinds and the machine's load): a signal (Ctrl-C, SIGTERM) is
taken between two calls, never inside one (a record of 2e6 samples through 50 elements held
one call for 17 s)."""


def open_loop_calls(codes, params, s, s_prev, scalars, x, h, i0, glt, glw):
    """:func:`open_loop_chunk` in calls of at most :data:`CALL_ELEMENT_STEPS` element steps,
    the state carried from one to the next: the same numbers as one call.

    Parameters
    ----------
    codes, params, s, s_prev, scalars, x, h, i0, glt, glw
        As :func:`open_loop_chunk` (`s`, `s_prev`, `scalars` updated in place).

    Returns
    -------
    ndarray
        The link force at the samples `x` [N].

    Examples
    --------
    >>> from motionhyst.hysteresis import Jenkins
    >>> st = Jenkins(k=1e4, fc=5.0).time_stepping()
    >>> x = 0.002 * np.sin(np.linspace(0.0, 20.0, 3001))
    >>> s = np.array(st.state0, dtype=float)
    >>> w = open_loop_calls(st.codes, st.params, s, s.copy(), np.zeros(2), x, 1e-3, 0, GL_T,
    ...                     GL_W)
    >>> bool(np.array_equal(w, open_loop(st.codes, st.params, st.state0, x, 1e-3, GL_T, GL_W)))
    True
    """
    x = np.ascontiguousarray(x, dtype=float)
    step = max(1, CALL_ELEMENT_STEPS // max(int(codes.shape[0]), 1))
    if x.size <= step:
        return open_loop_chunk(codes, params, s, s_prev, scalars, x, h, i0, glt, glw)
    out = np.empty(x.size)
    for a in range(0, x.size, step):
        out[a:a + step] = open_loop_chunk(codes, params, s, s_prev, scalars, x[a:a + step], h,
                                          i0 + a, glt, glw)
    return out


def open_loop(codes, params, s0, x, h, glt, glw):
    """Force of the elements for the displacement samples `x` (step `h`), from rest at ``x[0]``.

    Parameters
    ----------
    codes : ndarray of int
        Element codes of a :class:`Stepping` (``Stepping.codes``).
    params : ndarray
        Element parameters (``Stepping.params``).
    s0 : array_like
        Initial element states (``Stepping.state0``: at rest).
    x : array_like
        Displacement samples [m].
    h : float
        Time step between samples [s].
    glt : ndarray
        Gauss-Legendre nodes on [0, 1] of the rate-dependent elements' step (:data:`GL_T`).
    glw : ndarray
        Their weights (:data:`GL_W`).

    Examples
    --------
    >>> from motionhyst.hysteresis import Dahl
    >>> st = Dahl(k=1e4, fc=5.0).time_stepping()
    >>> w = open_loop(st.codes, st.params, st.state0, np.linspace(0.0, 0.01, 101), 1e-3,
    ...               GL_T, GL_W)
    >>> bool(0.0 < w[-1] < 5.0)                  # approaches the slip force fc from below
    True
    """
    s = np.array(s0, dtype=float)
    return open_loop_calls(codes, params, s, s.copy(), np.zeros(2), x, h, 0, glt, glw)

