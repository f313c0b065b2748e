"""A link without inertia in time: displacement from force, and force from displacement.

The :class:`~motionhyst.plants.quasi_static.QuasiStatic` plant has no mass: at
every sample the force balances the link and the optional parallel spring and
damper,

.. math::

    u_n + f_0 = w_n + k\\, x_n + c\\, v_n, \\qquad
    v_n = \\frac{3 x_n - 4 x_{n-1} + x_{n-2}}{2 h},

``w_n`` the link's force after its exact update over the step from
``x_{n-1}`` to ``x_n`` (:func:`~motionhyst.hysteresis.stepping.advance`, the
displacement linear in time over the step ``h``), ``v_n`` the velocity by the
second-order backward difference (stable for a damper of any time constant
``c / k``, shorter than a step or not; the rates inside LuGre's force are
taken alike).  Before the first sample the link is relaxed at ``x = 0``
(the first velocity ``x_0 / h``), or, for the force, where the caller says
(``x_before``: ``motionhyst predict`` takes it relaxed at the record's first
displacement, as a force-displacement fit does).

* Force from displacement (:func:`force_from_displacement`) evaluates the
  right-hand side: one pass of the link's update.
* Displacement from force (:func:`displacement_from_force`) solves the
  balance for ``x_n`` sample by sample: the right-hand side grows with
  ``x_n`` for every passive link, so the root is bracketed outward from
  ``x_{n-1}`` and refined by the Illinois method to rounding.  A rigid
  slider (``model = "coulomb"``) that holds the force sticks exactly.  A
  force that nothing holds (a slip force exceeded with neither spring nor
  damper in parallel) makes the displacement run away: an error, not a
  number.

No step smaller than the record's is needed (there is no mode to resolve),
so both directions run at the record's own samples, in memory of the record's
size.  Both use the same discretisation, so one undoes the other to rounding.

Examples
--------
>>> import numpy as np
>>> from motionhyst.hysteresis import Jenkins
>>> from motionhyst.plants import QuasiStatic
>>> plant, link = QuasiStatic(k=1e5), Jenkins(k=4e5, fc=20.0)
>>> t = np.arange(400) / 1000.0
>>> x = 1e-4 * np.sin(2 * np.pi * 5 * t)
>>> u = force_from_displacement(plant, link, t, x)
>>> bool(np.allclose(displacement_from_force(plant, link, t, u), x, rtol=0, atol=1e-15))
True
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.compiled import njit
from motionhyst.hysteresis.along_stroke import FIXED_IN_OPEN_LOOP, AlongStroke
from motionhyst.hysteresis.base import Hysteresis
from motionhyst.hysteresis.stepping import (
    COULOMB,
    GL_T,
    GL_W,
    Stepping,
    advance,
    open_loop_calls,
)
from motionhyst.time.periodic_runs import periodic_output
from motionhyst.time.resample import check_record, sampling_rate

__all__ = ["MAX_BRACKET_DOUBLINGS", "displacement_from_force", "force_from_displacement"]

#: A step's displacement is searched over at most this many doublings of its first guess;
#: a balance not bracketed by then is a force the link, spring and damper do not hold
MAX_BRACKET_DOUBLINGS = 400
_MAX_REFINE = 200


@njit(cache=True)
def _link_force(codes, params, s, s_prev, s_new, dx, dx_prev, h, first, glt,
                glw):  # pragma: no cover - compiled
    """The link's force after a step `dx` (the new states into `s_new`)."""
    w = 0.0
    for j in range(codes.shape[0]):
        sj, f = advance(codes[j], params[j], s[j], s_prev[j], dx, dx_prev, h, h, first, glt,
                        glw)
        s_new[j] = sj
        w += f
    return w


@njit(cache=True)
def _stuck(codes, params, s, s_prev, s_new, dx_prev, h, first, glt, glw, need,
           ):  # pragma: no cover - compiled
    """With rigid sliders: 0 if they hold `need` (force beyond the rest's, states set), else
    +1 / -1 for the direction they slip in."""
    lo = 0.0
    hi = 0.0
    rest = 0.0
    for j in range(codes.shape[0]):
        if codes[j] == COULOMB:
            hi += params[j, 0]
            lo -= params[j, 1]
        else:
            sj, f = advance(codes[j], params[j], s[j], s_prev[j], 0.0, dx_prev, h, h, first,
                            glt, glw)
            s_new[j] = sj
            rest += f
    held = need - rest
    if held > hi:
        return 1
    if held < lo:
        return -1
    span = hi - lo
    for j in range(codes.shape[0]):  # each slider its share of the held force
        if codes[j] == COULOMB:
            share = (params[j, 0] + params[j, 1]) / span if span > 0.0 else 0.0
            s_new[j] = held * share
    return 0


@njit(cache=True)
def quasi_static_run(codes, params, s, s_prev, scalars, u, k, c, h, slope, glt,
                     glw):  # pragma: no cover - compiled
    """Displacements balancing the forces `u` (offset included) sample by sample.

    ``scalars = (x_prev, dx_prev, first)`` and the element states `s`, `s_prev`
    are carried in place (a run continues where the last ended).  `slope` is an
    upper estimate of the balance's stiffness ``k + c / h + k_link`` (the first
    guess of a step).  Returns the displacements; NaN from the sample on where
    the balance could not be bracketed (the force is not held).
    """
    n = u.shape[0]
    out = np.empty(n)
    n_el = codes.shape[0]
    s_new = np.empty(n_el)
    s_try = np.empty(n_el)
    has_slider = False
    for j in range(n_el):
        if codes[j] == COULOMB:
            has_slider = True
    x_prev = scalars[0]
    dx_prev = scalars[1]
    first = scalars[2] != 0.0
    for i in range(n):
        # the link's force plus k dx and the damper's share of dx must equal `need`; the
        # velocity by the second-order backward difference (the first step's: dx / h)
        if first:
            cd = c / h
            need = u[i] - k * x_prev
        else:
            cd = 1.5 * c / h
            need = u[i] - k * x_prev + 0.5 * c * dx_prev / h
        direction = 0
        if has_slider:
            direction = _stuck(codes, params, s, s_prev, s_new, dx_prev, h, first, glt, glw,
                               need)
            dx = 0.0
        if direction == 0 and has_slider:
            dx = 0.0
        else:
            r0 = _link_force(codes, params, s, s_prev, s_try, 0.0, dx_prev, h, first, glt,
                             glw) - need
            if not has_slider:
                if r0 == 0.0:
                    direction = 0
                    for j in range(n_el):
                        s_new[j] = s_try[j]
                elif r0 < 0.0:
                    direction = 1
                else:
                    direction = -1
            dx = 0.0
            if direction != 0:
                # bracket: a (residual of the wrong sign) .. b (the other sign)
                scale = abs(r0) if r0 != 0.0 else abs(need) + 1.0
                step = scale / slope if slope > 0.0 else 1e-12 * (abs(x_prev) + 1e-6)
                if not step > 0.0 or not math.isfinite(step):
                    step = 1e-12 * (abs(x_prev) + 1e-6)
                a = 0.0
                ra = -1.0 * direction  # the sign it has before the root
                b = direction * step
                rb = 0.0
                found = False
                for _ in range(MAX_BRACKET_DOUBLINGS):
                    rb = (_link_force(codes, params, s, s_prev, s_try, b, dx_prev, h, first,
                                      glt, glw) + (k + cd) * b - need)
                    if not math.isfinite(rb):
                        break
                    if rb * direction >= 0.0:
                        found = True
                        break
                    a = b
                    ra = rb
                    b *= 2.0
                if not found:
                    for m in range(i, n):
                        out[m] = np.nan
                    return out
                if a == 0.0:
                    ra = (_link_force(codes, params, s, s_prev, s_try, 0.0, dx_prev, h, first,
                                      glt, glw) - need)
                    if has_slider:  # the slider's force jumps at 0: take its slipping side
                        ra = -1.0 * direction * max(abs(ra), 1e-300)
                side = 0
                for _ in range(_MAX_REFINE):  # Illinois on [a, b]
                    if rb == 0.0 or abs(b - a) <= 4e-16 * (abs(x_prev) + abs(a) + abs(b)):
                        break
                    if ra != rb and (ra < 0.0) != (rb < 0.0):
                        m = b - rb * (b - a) / (rb - ra)
                    else:
                        m = 0.5 * (a + b)
                    if not (min(a, b) < m < max(a, b)):
                        m = 0.5 * (a + b)
                    rm = (_link_force(codes, params, s, s_prev, s_try, m, dx_prev, h, first,
                                      glt, glw) + (k + cd) * m - need)
                    if rm == 0.0:
                        a = m
                        b = m
                        rb = 0.0
                        break
                    if (rm < 0.0) == (rb < 0.0):
                        b = m
                        rb = rm
                        if side == 1:
                            ra *= 0.5
                        side = 1
                    else:
                        a = m
                        ra = rm
                        if side == -1:
                            rb *= 0.5
                        side = -1
                dx = b
                _link_force(codes, params, s, s_prev, s_new, dx, dx_prev, h, first, glt, glw)
        for j in range(n_el):
            s_prev[j] = s[j]
            s[j] = s_new[j]
        x_prev += dx
        dx_prev = dx
        first = False
        out[i] = x_prev
    scalars[0] = x_prev
    scalars[1] = dx_prev
    scalars[2] = 0.0
    return out


def _parts(plant, link: Hysteresis | None) -> tuple[Stepping, float, float, float]:
    """The link's rows and the plant's ``k``, ``c``, ``f0`` (a quasi-static plant only)."""
    if plant.has_inertia:
        raise ValueError(f"a {plant.name} has inertia: its response needs its masses "
                         f"(motionhyst.time.openloop.OpenLoop), not the quasi-static balance")
    if isinstance(link, AlongStroke):
        raise ValueError(FIXED_IN_OPEN_LOOP)
    st = Stepping.empty() if link is None else link.time_stepping()
    return st, float(plant.k), float(plant.c), float(plant.force_offset)


def _link_stiffness(link: Hysteresis | None) -> float:
    if link is None:
        return 0.0
    k = float(link.initial_stiffness)
    return k if math.isfinite(k) else 0.0


def displacement_from_force(plant, link: Hysteresis | None, t: ArrayLike, force: ArrayLike, *,
                            periodic: bool = False,
                            initial: tuple[float, ArrayLike] | None = None
                            ) -> NDArray[np.float64]:
    """The displacement where a quasi-static plant's link balances a force record.

    Parameters
    ----------
    plant : QuasiStatic
        The plant: ``k``, ``c`` in parallel with the link, ``force_offset``.
    link : Hysteresis or None
        The link's model (any model with a time step); None: the spring and
        damper alone.
    t : array_like
        Uniform time grid [s], at least 2 samples.
    force : array_like
        Force at the instants `t` [N].
    periodic : bool
        False: from the link relaxed at ``x = 0`` before the first sample.
        True: `force` holds whole periods; the periodic steady state (periods
        repeated until the displacement repeats).
    initial : (float, array_like), optional
        Not periodic: the displacement before the first sample [m] and the link's element
        states there (``Stepping.state0``'s layout; default ``(0, state0)``, relaxed at 0): a
        record cut from a longer run.

    Returns
    -------
    ndarray
        Displacement at the samples [m].

    Raises
    ------
    ValueError
        A force that the link, spring and damper do not hold (the displacement
        would run away), naming the instant; a plant with inertia.

    Examples
    --------
    A Jenkins link alone holds up to its slip force; a parallel damper takes the rest:

    >>> import numpy as np
    >>> from motionhyst.hysteresis import Jenkins
    >>> from motionhyst.plants import QuasiStatic
    >>> t = np.arange(5) * 1e-3
    >>> u = np.array([0.0, 5.0, 10.0, 10.0, 12.0])
    >>> x = displacement_from_force(QuasiStatic(c=2.0), Jenkins(k=1e4, fc=10.0), t, u)
    >>> [round(float(v) * 1e3, 4) for v in x]   # mm; beyond fc = 10 N only the damper resists
    [0.0, 0.3846, 0.8876, 1.0552, 1.7778]
    >>> try:
    ...     displacement_from_force(QuasiStatic(), Jenkins(k=1e4, fc=10.0), t, u)
    ... except ValueError as exc:
    ...     print(str(exc).split(":")[0])
    at t = 0.004 s the force 12 N is not held
    """
    tt, u = check_record(t, force)
    h = 1.0 / sampling_rate(tt)
    st, k, c, f0 = _parts(plant, link)
    slope = k + c / h + _link_stiffness(link)
    uf = np.ascontiguousarray(u + f0, dtype=float)
    x_before, s0 = (0.0, st.state0) if initial is None else initial
    s0 = np.array(s0, dtype=float).reshape(np.shape(st.state0))
    state = [s0, s0.copy(), np.array([float(x_before), 0.0, 1.0])]

    def run() -> NDArray[np.float64]:
        x = quasi_static_run(st.codes, st.params, state[0], state[1], state[2], uf, k, c, h,
                             slope, GL_T, GL_W)
        bad = np.flatnonzero(~np.isfinite(x))
        if bad.size:
            i = int(bad[0])
            raise ValueError(f"at t = {tt[i]:.6g} s the force {u[i]:.6g} N is not held: the "
                             f"link's force with the spring k = {k:.6g} N/m and the damper "
                             f"c = {c:.6g} N s/m cannot balance it (the displacement runs "
                             f"away; a quasi-static plant needs k or c, or a link that "
                             f"stiffens, for such a force)")
        return x

    if not periodic:
        return run()

    def next_period():
        x = run()
        return np.append(x, x[-1]), np.zeros((x.size + 1, 0)), True

    y, _ = periodic_output(next_period, 50, floating=False, sensitivities=False)
    return y


def force_from_displacement(plant, link: Hysteresis | None, t: ArrayLike,
                            displacement: ArrayLike, *, periodic: bool = False,
                            x_before: float = 0.0) -> NDArray[np.float64]:
    """The force that holds a quasi-static plant at a displacement record.

    ``u_n = w_n + k x_n + c v_n - f0`` (``v_n`` the second-order backward
    difference) with ``x_{-1} = x_before`` and the link relaxed there, at rest
    (with ``x_before = 0``, the inverse of :func:`displacement_from_force`).

    Parameters
    ----------
    plant : QuasiStatic
        The plant: ``k``, ``c`` in parallel with the link, ``force_offset``.
    link : Hysteresis or None
        The link's model; None: the spring and damper alone.
    t : array_like
        Uniform time grid [s], at least 2 samples.
    displacement : array_like
        Displacement at the instants `t` [m].
    periodic : bool
        True: `displacement` holds whole periods; the force of the periodic
        steady state (the first period's run forgotten).
    x_before : float
        Displacement before the first sample [m], where the link is relaxed and at
        rest: 0 for a link relaxed at ``x = 0``; the first sample's displacement for
        a record cut from a run (or read by a sensor with a zero offset) whose link
        is taken relaxed where the record starts, as a force-displacement fit takes
        it (``motionhyst predict``).

    Returns
    -------
    ndarray
        Force at the samples [N].

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.hysteresis import Jenkins
    >>> from motionhyst.plants import QuasiStatic
    >>> t = np.arange(4) * 1e-3
    >>> u = force_from_displacement(QuasiStatic(k=1e3), Jenkins(k=1e4, fc=10.0), t,
    ...                             [0.0, 5e-4, 2e-3, 1e-3])
    >>> [round(float(v), 9) for v in u]                 # k x + the link (slips at 10 N)
    [0.0, 5.5, 12.0, 1.0]
    >>> u = force_from_displacement(QuasiStatic(k=1e3), Jenkins(k=1e4, fc=10.0), t,
    ...                             [1e-3, 1.5e-3, 3e-3, 2e-3], x_before=1e-3)
    >>> [round(float(v), 9) for v in u]                 # the link relaxed at 1 mm
    [1.0, 6.5, 13.0, 2.0]
    """
    tt, x = check_record(t, displacement, what="displacement")
    h = 1.0 / sampling_rate(tt)
    st, k, c, f0 = _parts(plant, link)
    xs = np.ascontiguousarray(x, dtype=float)
    s = np.array(st.state0, dtype=float)
    s_prev = s.copy()
    scalars = np.array([float(x_before), 0.0])  # (x_prev, dx_prev): relaxed, at rest
    done = [1]  # samples run, counting the relaxed one before the first

    def run() -> NDArray[np.float64]:
        x_prev, dx_prev = scalars[0], scalars[1]
        w = open_loop_calls(st.codes, st.params, s, s_prev, scalars, xs, h, done[0], GL_T,
                            GL_W)
        dx = np.diff(xs, prepend=x_prev)
        dx_before = np.concatenate([[dx_prev], dx[:-1]])
        v = (1.5 * dx - 0.5 * dx_before) / h
        if done[0] == 1:  # the first step: its own velocity
            v[0] = dx[0] / h
        done[0] += xs.size
        return w + k * xs + c * v - f0

    if not periodic:
        return run()
    out = run()
    if not st.codes.size:
        return out
    for _ in range(49):
        prev, out = out, run()
        if np.max(np.abs(out - prev)) <= 1e-12 * max(float(np.max(np.abs(out))), 1e-300):
            return out
    raise ValueError("the periodic steady state was not reached (the force does not settle "
                     "from one period to the next)")
