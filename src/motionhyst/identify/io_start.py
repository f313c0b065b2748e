"""The linear start of an input-output identification: the best linear approximation.

The mass-spring-damper ``1 / (m s^2 + c s + k)`` (:func:`best_linear_approximation`)
and the floating two-mass stage of eqs. (1)-(2) held by a spring and damper in
place of its link (:func:`best_linear_approximation_two_mass`, its response
:func:`two_mass_response`), fitted to the records' frequency response, or, for
records from rest, to that of an ARX model of them.  Starts for the
simulation-error fits, not results.
"""

from __future__ import annotations

import math
import os

import numpy as np
from numpy.typing import NDArray

from motionhyst.identify.io_offsets import Extras
from motionhyst.identify.io_rates import savgol_derivative
from motionhyst.identify.io_records import IORecord, segment_records
from motionhyst.time.openloop import MassSpringDamper, TwoMass

__all__ = ["best_linear_approximation", "best_linear_approximation_two_mass", "equation_rows",
           "reference_mass"]

BLA_STARTS = 6  # two-mass: grid points refined
#: The fewest lines of the records' frequency response a two-mass stage is fitted to: its
#: linear model (``m1, m2, b, k`` and the link's ``kl, cl``) has 6 parameters, and 4 complex
#: lines give 8 numbers, more than it takes to pass through them
TWO_MASS_LINES = 4


def best_linear_approximation(records: list[IORecord]) -> MassSpringDamper:
    """``m, c, k`` of ``1 / (m s^2 + c s + k)`` fitted to the records' frequency response.

    ``G(f) = sum Y U* / sum |U|^2`` over the records (each transformed whole),
    at the lines whose input power is at least ``1e-3`` of the largest; the
    fit minimises ``sum |G| ^2 |1/G - (k - m w^2 + j c w)|^2``.  Negative
    estimates are clipped to small positive values (a start, not a result).

    Parameters
    ----------
    records : list of IORecord
        Force in, displacement out; one sampling rate.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.time.openloop import MassSpringDamper, OpenLoop
    >>> t = np.arange(4096) / 750
    >>> u = np.random.default_rng(0).standard_normal(4096)
    >>> y = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4)).simulate(t, u, periodic=True).displacement
    >>> p = best_linear_approximation([IORecord(t, u, y)])
    >>> round(p.m, 3), round(p.c, 2), round(p.k)
    (2.0, 10.0, 50000)
    """
    f, G = _spectral_response(records)
    w = 2 * np.pi * f
    wt = np.abs(G)
    inv = 1.0 / G
    # rows: Re(1/G) = k - m w^2 ; Im(1/G) = c w
    A = np.zeros((2 * w.size, 3))
    b = np.concatenate([inv.real, inv.imag])
    A[: w.size, 0] = -w ** 2
    A[: w.size, 2] = 1.0
    A[w.size:, 1] = w
    ww = np.concatenate([wt, wt])
    m, c, k = np.linalg.lstsq(A * ww[:, None], b * ww, rcond=None)[0]
    m = abs(m) if m != 0 else 1.0
    return MassSpringDamper(m, max(c, 1e-6 * m * w.min()), max(k, 1e-6 * m * w.min() ** 2))


def inverse_dynamics(records: list[IORecord], floating: bool, asymmetric: bool = False
                     ) -> dict[str, float]:
    """The records' linear estimate of a single mass: least squares on the equation of motion.

    ``u = m y'' + c y' + f sign(y') + u0`` (a floating stage: viscous and Coulomb
    friction) or ``u = m y'' + c y' + k y + u0`` (on a spring), the rates of the
    position from a cubic Savitzky-Golay filter over about 10 ms (at least 7
    samples): the inverse-dynamics estimate of the EMPS benchmark's reference
    model (IDIM-LS, Janot et al. 2019).  Linear in its parameters whatever the
    model, it is what a simulation-error fit's mass is compared with, and where
    a positioning axis's fit starts.

    Parameters
    ----------
    records : list of IORecord
        The records.
    floating : bool
        No spring to the ground (the Coulomb term instead of the spring's).
    asymmetric : bool
        A floating stage's viscous friction by direction: ``c_pos q'`` moving
        forward, ``c_neg q'`` backward, in place of ``c q'`` (a direction-dependent
        Coulomb force is a force offset while the stage moves: not told apart).

    Returns
    -------
    dict
        ``m, c, u0`` and ``fc`` (floating) or ``k``; with `asymmetric` also ``c_pos``
        and ``c_neg`` (``c`` their mean).

    Examples
    --------
    >>> t = np.arange(3000) / 1000.0
    >>> y = 0.05 * np.sin(2 * np.pi * t) + 0.02 * np.sin(2 * np.pi * 3.3 * t)
    >>> v = np.gradient(y, t, edge_order=2)
    >>> u = 2.0 * np.gradient(v, t, edge_order=2) + 30.0 * v + 4.0 * np.sign(v) - 1.5
    >>> est = inverse_dynamics([IORecord(t, u, y)], floating=True)
    >>> {k: round(v, 1) for k, v in est.items()}
    {'m': 2.0, 'c': 30.0, 'fc': 4.0, 'u0': -1.5}
    >>> u2 = u + 10.0 * np.maximum(v, 0.0)                   # 10 N s/m more moving forward
    >>> est = inverse_dynamics([IORecord(t, u2, y)], floating=True, asymmetric=True)
    >>> round(est["c_pos"], 1), round(est["c_neg"], 1)
    (40.0, 30.0)
    """
    x, _ = _least_squares(records, floating, asymmetric)
    if x.size == 5:
        m, c_pos, c_neg, third, u0 = x
        return {"m": float(m), "c": float(0.5 * (c_pos + c_neg)), "fc": float(third),
                "u0": float(u0), "c_pos": float(c_pos), "c_neg": float(c_neg)}
    m, c, third, u0 = x
    return {"m": float(m), "c": float(c), "fc" if floating else "k": float(third),
            "u0": float(u0)}


def _least_squares(records: list[IORecord], floating: bool, asymmetric: bool = False
                   ) -> tuple[NDArray[np.float64], float]:
    """:func:`inverse_dynamics`'s solution and the share of the force it leaves
    unexplained (``||A x - u|| / ||u - mean(u)||``)."""
    rows, rhs = equation_rows(records, floating, asymmetric)
    A, u = np.concatenate(rows), np.concatenate(rhs)
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    x = np.linalg.lstsq(A / scale, u, rcond=None)[0] / scale
    spread = float(np.linalg.norm(u - np.mean(u)))
    return x, float(np.linalg.norm(A @ x - u)) / spread if spread > 0 else math.inf


#: The records' linear model is a reference for a fit's mass only where it explains the
#: force: at most this share of it unexplained (EMPS: 0.045; a stage whose link carries
#: the force, or a second mass, leaves 0.7-1)
LINEAR_MODEL_RESIDUAL = 0.3


def reference_mass(records: list[IORecord], floating: bool) -> float:
    """The mass a fit's is compared with: :func:`inverse_dynamics`'s, where that linear
    model explains the records' force (:data:`LINEAR_MODEL_RESIDUAL`), else NaN.

    A stage whose link carries much of the force (a Jenkins link before it slips), or
    whose second mass moves on its own, is no rigid body with friction: its linear
    estimate of the mass is then off by any factor and says nothing of the fit's.

    Parameters
    ----------
    records : list of IORecord
        The records.
    floating : bool
        No spring to the ground (as :func:`inverse_dynamics`).

    Returns
    -------
    float
        The mass [kg], or NaN.

    Examples
    --------
    >>> t = np.arange(3000) / 1000.0
    >>> y = 0.05 * np.sin(2 * np.pi * t) + 0.02 * np.sin(2 * np.pi * 3.3 * t)
    >>> v = np.gradient(y, t, edge_order=2)
    >>> u = 2.0 * np.gradient(v, t, edge_order=2) + 30.0 * v + 4.0 * np.sign(v) - 1.5
    >>> round(reference_mass([IORecord(t, u, y)], floating=True), 2)
    2.0
    >>> u_link = u + 400.0 * y                  # a spring the floating model does not have
    >>> reference_mass([IORecord(t, u_link, y)], floating=True)
    nan
    """
    x, unexplained = _least_squares(records, floating)
    return float(x[0]) if unexplained <= LINEAR_MODEL_RESIDUAL else math.nan


def equation_rows(records: list[IORecord], floating: bool, asymmetric: bool = False,
                  window: int | None = None, light: bool = False
                  ) -> tuple[list[NDArray[np.float64]], list[NDArray[np.float64]]]:
    """The rows of :func:`inverse_dynamics`'s least squares, record by record.

    Parameters
    ----------
    records, floating, asymmetric
        As :func:`inverse_dynamics`.
    window : int, optional
        Samples of the Savitzky-Golay filter (odd, at least 5; default about 10 ms,
        at least 7).
    light : bool
        The rates by :func:`~motionhyst.identify.io_rates.savgol_derivative`, numpy alone
        (the inertia check, which refuses a record before scipy loads); else by
        :func:`scipy.signal.savgol_filter`, the same filter to round-off (the fits' start).

    Returns
    -------
    rows : list of ndarray
        For each record, the regressors at each sample: acceleration, velocity (or
        its two directions), ``sign(y')`` (floating) or ``y``, and 1 (the offset).
    rhs : list of ndarray
        For each record, its force.

    Examples
    --------
    >>> t = np.arange(200) / 100.0
    >>> rows, rhs = equation_rows([IORecord(t, np.sin(t), 1e-3 * t ** 2)], floating=False)
    >>> rows[0].shape, np.round(rows[0][100, :2], 6).tolist()         # y'' = 2e-3, y' = 2e-3 t
    ((200, 4), [0.002, 0.002])
    """
    rate = savgol_derivative
    if not light:
        from scipy.signal import savgol_filter

        def rate(y, samples, deriv, dt):
            return savgol_filter(y, samples, 3, deriv=deriv, delta=dt)

    rows, rhs = [], []
    for rec in records:
        samples = window or max(7, 2 * round(0.005 * rec.fs) + 1)
        samples = min(samples, rec.y.size - (1 - rec.y.size % 2))
        dt = 1.0 / rec.fs
        v = rate(rec.y, samples, 1, dt)
        a = rate(rec.y, samples, 2, dt)
        third = np.sign(v) if floating else rec.y
        viscous = ([np.maximum(v, 0.0), np.minimum(v, 0.0)] if asymmetric and floating
                   else [v])
        rows.append(np.column_stack([a, *viscous, third, np.ones_like(v)]))
        rhs.append(rec.u)
    return rows, rhs


def _spectral_response(records: list[IORecord]
                       ) -> tuple[NDArray[np.float64], NDArray[np.complex128]]:
    """``G(f) = sum Y U* / sum |U|^2`` over the records (each transformed whole), at the
    lines whose input power is at least ``1e-3`` of the largest."""
    n_max = max(r.u.size for r in records)
    freqs = np.fft.rfftfreq(n_max, 1.0 / records[0].fs)
    suy = np.zeros(freqs.size, dtype=complex)
    suu = np.zeros(freqs.size)
    for r in records:
        f = np.fft.rfftfreq(r.u.size, 1.0 / r.fs)
        U = np.fft.rfft(r.u - r.u.mean())
        Y = np.fft.rfft(r.y - r.y.mean())
        idx = np.clip(np.searchsorted(freqs, f), 0, freqs.size - 1)
        np.add.at(suy, idx, Y * np.conj(U))
        np.add.at(suu, idx, np.abs(U) ** 2)
    sel = (suu >= 1e-3 * suu.max()) & (freqs > 0)
    return freqs[sel], suy[sel] / suu[sel]


def _arx_response(records: list[IORecord], f_hz: NDArray[np.float64], na: int = 4,
                  nb: int = 6) -> NDArray[np.complex128]:
    """Frequency response at `f_hz` of an ARX model fitted to records from rest.

    ``y[n] + a_1 y[n-1] + ... + a_na y[n-na] = b_0 u[n] + ... + b_(nb-1) u[n-nb+1]``
    by least squares over every record (zero before the first sample: from
    rest).  The records' spectra would see the free ringing of a lightly damped
    mode started by the record's start as a response to the force; the
    recursion carries it.
    """
    rows, rhs = [], []
    for rec in records:
        n = rec.y.size
        yp = np.concatenate([np.zeros(na), rec.y])
        up = np.concatenate([np.zeros(nb), rec.u])
        cols = [-yp[na - i:na - i + n] for i in range(1, na + 1)]
        cols += [up[nb - i:nb - i + n] for i in range(nb)]
        rows.append(np.column_stack(cols))
        rhs.append(rec.y)
    A = np.concatenate(rows)
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    theta = np.linalg.lstsq(A / scale, np.concatenate(rhs), rcond=None)[0] / scale
    z1 = np.exp(-2j * np.pi * f_hz / records[0].fs)
    den = 1.0 + sum(theta[i - 1] * z1 ** i for i in range(1, na + 1))
    num = sum(theta[na + i] * z1 ** i for i in range(nb))
    return num / den


def two_mass_response(theta: NDArray[np.float64], f_hz: NDArray[np.float64], at_link: bool
                      ) -> NDArray[np.complex128]:
    """``y2 / u`` or, `at_link`, ``y1 / u`` of the two-mass stage (eqs. 1-2) held by a spring
    ``kl`` and damper ``cl`` on ``y1``; ``theta = (m1, m2, b, k, kl, cl)``.

    With ``D = (m1 s^2 + (b + cl) s + k + kl)(m2 s^2 + b s + k) - (b s + k)^2``:
    ``y2 / u = (b s + k) / D`` and ``y1 / u = (m2 s^2 + b s + k) / D``.
    """
    m1, m2, b, k, kl, cl = theta
    s = 2j * np.pi * f_hz
    inner = b * s + k
    D = (m1 * s * s + (b + cl) * s + k + kl) * (m2 * s * s + inner) - inner * inner
    return (m2 * s * s + inner if at_link else inner) / D


def best_linear_approximation_two_mass(records: list[IORecord], output: str = "y2",
                                       periodic: bool = True) -> tuple[TwoMass, float, float]:
    """The two-mass stage and a spring and damper for its link fitted to the records'
    frequency response.

    The link is linearised as a spring ``kl`` and damper ``cl`` from ``y1`` to
    the ground (:func:`two_mass_response`).  The impedance at ``y1`` is

    .. math::

        Z_1 = \\frac{1}{G_1} = m_1 s^2 + c_l s + k_l + m_2 s^2 H(s), \\qquad
        H = \\frac{y_2}{y_1} = \\frac{2 \\zeta \\omega s + \\omega^2}
        {s^2 + 2 \\zeta \\omega s + \\omega^2},

    with ``omega^2 = k / m2`` and ``2 zeta omega = b / m2`` (and ``1/G2 = Z1 / H``
    when ``y2`` is measured), linear in ``(m1, cl, kl, m2)`` for given
    ``(omega, zeta)``: those four are solved by weighted linear least squares
    (relative error) on a grid of ``omega`` across and beyond the excited band
    and of ``zeta`` from 0.005 to 0.3, and the best point is refined in all six
    parameters (``log`` of each) by nonlinear least squares on the relative
    error of ``G`` (:func:`_spectral_response`).  A start for the simulation-error
    fit, not a result.

    Parameters
    ----------
    records : list of IORecord
        Force in, displacement out; one sampling rate.
    output : {"y2", "y1"}
        The measured position.
    periodic : bool
        Records are whole periods of a steady state (else from rest).

    Returns
    -------
    plant : TwoMass
        The stage's start values.
    k_link, c_link : float
        The link's linear stiffness [N/m] and damping [N s/m].

    Raises
    ------
    ValueError
        One line when the records do not determine a second mass: the best fit's internal
        mode (``sqrt(k (m1 + m2) / (m1 m2))``) above the records' Nyquist frequency, or
        outside the band of the lines they excite (its resonance is not in them), or the
        lighter mass's standard error (from the fit's Jacobian and residual) as large as
        its value.  Their masses then move as one, the records are a single mass's (a
        two-mass fit would spend its search on parameters the records do not determine: a
        10 kg axis's record, its best fit 0.0098 and 9.8 kg with its mode at 314 Hz beside
        lines of 1-4.25 Hz, ran to the work budget), however light or heavy a second mass
        is (a 0.5 kg carriage on a 60 kg stage whose mode the records excite is
        determined).  Also when the records excite fewer than :data:`TWO_MASS_LINES`
        lines, too few to determine a two-mass stage at all.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.time.openloop import OpenLoop, TwoMass
    >>> from motionhyst.hysteresis import BoucWen
    >>> t = np.arange(4096) / 750
    >>> u = np.random.default_rng(0).standard_normal(4096)
    >>> spring = BoucWen.from_general(5e4, 1.0, 0.0, 0.0, 1.0)   # beta = 0: a spring
    >>> y = OpenLoop(TwoMass(2.0, 3.0, 20.0, 2e5), spring).simulate(t, u, periodic=True)
    >>> p, kl, cl = best_linear_approximation_two_mass([IORecord(t, u, y.displacement)])
    >>> round(p.m1, 3), round(p.m2, 3), round(p.b, 2), round(p.k), round(kl), round(cl, 6)
    (2.0, 3.0, 20.0, 200000, 50000, 0.0)
    """
    mech = TwoMass(1.0, 1.0, 0.0, 1.0, output).mechanics()
    at_link = mech.output == mech.link  # y1 measured: the link's own position
    f, G = _spectral_response(records)
    keep = f < 0.5 * records[0].fs * (1 - 1e-9)  # the Nyquist line is ambiguous
    f, G = f[keep], G[keep]
    names = records[0].name if len(records) == 1 else f"{records[0].name} and the others"
    if f.size < TWO_MASS_LINES:  # fewer numbers than the linear model's parameters
        raise ValueError(f"{names}: the records do not show two masses: they excite "
                         f"{f.size} line(s) of their frequency response "
                         f"({', '.join(f'{v:.3g}' for v in f)} Hz), {2 * f.size} numbers for "
                         f"the 6 parameters of a two-mass stage on the link's linear spring "
                         f"and damper: a second mass is not determined; identify a single "
                         f"mass (--plant mass-spring-damper or mass-damper), or give a record "
                         f"that excites more frequencies (a multisine, a sweep)")
    if not periodic:
        G = _arx_response(records, f)
    s = 2j * np.pi * f
    grid = []
    for om in 2 * np.pi * np.geomspace(0.5 * f[0], 10 * f[-1], 80):
        for zeta in np.geomspace(0.002, 0.5, 12):
            H = (2 * zeta * om * s + om * om) / (s * s + 2 * zeta * om * s + om * om)
            Z = 1.0 / G if at_link else H / G
            A = np.column_stack([s * s, s, np.ones_like(s), s * s * H]) / np.abs(Z)[:, None]
            rhs = Z / np.abs(Z)
            x = np.linalg.lstsq(np.concatenate([A.real, A.imag]),
                                np.concatenate([rhs.real, rhs.imag]), rcond=None)[0]
            m1, cl, kl, m2 = x
            if m1 > 0 and m2 > 0 and kl > 0:
                cost = float(np.sum(np.abs(A @ x - rhs) ** 2))
                grid.append((cost, m1, m2, 2 * zeta * om * m2, om * om * m2, kl, max(cl, 0.0)))
    if not grid:
        raise ValueError("the records' frequency response does not fit a two-mass stage on "
                         "a spring (no positive masses and stiffness)")
    mag = np.abs(G)

    def residual(logt):
        with np.errstate(all="ignore"):
            e = (two_mass_response(np.exp(logt), f, at_link) - G) / mag
        r = np.concatenate([e.real, e.imag])
        return np.where(np.isfinite(r), r, 1e6)

    from scipy.optimize import least_squares  # here: the inertia check needs no optimizer

    best = None
    for start in sorted(grid)[:BLA_STARTS]:  # the best grid points, refined in all six
        v = np.array(start[1:])
        v[-1] = max(v[-1], 1e-6 * math.sqrt(v[4] * (v[0] + v[1])))
        x0 = np.log(v)
        sol = least_squares(residual, x0, method="trf", xtol=1e-14, ftol=1e-14, gtol=1e-14,
                            max_nfev=200, bounds=(x0 - 30.0, x0 + 30.0))
        if best is None or sol.cost < best.cost:
            best = sol
    sol = best
    m1, m2, b, k, kl, cl = np.exp(sol.x)
    f_internal = math.sqrt(k * (m1 + m2) / (m1 * m2)) / (2 * math.pi)
    nyquist = 0.5 * records[0].fs
    if not f_internal < nyquist:  # the masses move as one within the records' band
        raise ValueError(f"{names}: the records show one mass, not two: the two-mass stage "
                         f"that fits their frequency response best has its internal mode at "
                         f"{f_internal:.3g} Hz, above their Nyquist frequency {nyquist:.3g} Hz; "
                         f"identify a single mass (--plant mass-spring-damper or mass-damper)")
    # the lighter mass's relative standard error: of its log, from the fit's Jacobian
    dof = max(sol.fun.size - sol.x.size, 1)
    cov = 2.0 * sol.cost / dof * np.linalg.pinv(sol.jac.T @ sol.jac)
    light = 0 if m1 <= m2 else 1
    std = math.sqrt(max(float(cov[light, light]), 0.0))
    why = (f"has its internal mode at {f_internal:.3g} Hz, outside the band of the lines they "
           f"excite ({f[0]:.3g}-{f[-1]:.3g} Hz)" if not f[0] <= f_internal <= f[-1] else
           f"has its lighter mass's standard error {std:.2g} times its value"
           if not std < 1.0 else None)
    if why is not None:  # the masses' split is not in the records
        raise ValueError(f"{names}: the records show one mass, not two: the two-mass stage "
                         f"that fits their frequency response best (masses of {m1:.3g} and "
                         f"{m2:.3g} kg) {why}: a second mass is not determined; identify a "
                         f"single mass (--plant mass-spring-damper or mass-damper), or give a "
                         f"record that excites the internal mode")
    return TwoMass(m1, m2, b, k, output), float(kl), float(cl)


MAX_FINE_SAMPLES = 50_000_000
"""Most integration steps of one simulation of the records (the work budget of a fit)."""


def check_substeps(records: list[IORecord], substeps: int, f_n: float | None,
                   factor: int = 1, sized: bool = False) -> None:
    """Refuse a fit whose records need too many integration steps, before it starts.

    The integration takes `substeps` steps per sample (``factor`` times as
    many input samples) to follow the stage's fastest mode `f_n`; a start
    whose mode lies far above the sample rate (a two-mass stage fitted to a
    record of one mass puts its second mass at any frequency) would
    otherwise ask for terabytes and hours.

    Parameters
    ----------
    records : list of IORecord
        The records.
    substeps : int
        Integration steps per sample.
    f_n : float or None
        The fastest mode of the start [Hz], which sets `substeps`; None: they are the
        least a stage runs (or what its link's stiffness at the start calls for).
    factor : int
        Input samples per integration step (2: the midpoints too).
    sized : bool
        The caller sizes the search's memory by its own, measured estimate (the Bouc-Wen
        link's, :func:`~motionhyst.identify.io_memory.check_bouc_wen_memory`): the steps
        alone are checked here.

    Raises
    ------
    ValueError
        One line: the steps, the mode, the remedy.

    Examples
    --------
    >>> import numpy as np
    >>> rec = IORecord(np.arange(100) / 750, np.zeros(100), np.zeros(100))
    >>> check_substeps([rec], 20, 700.0)
    >>> try:
    ...     check_substeps([rec], 10**7, 4e8)
    ... except ValueError as exc:
    ...     print(str(exc)[:43])
    the start's fastest mode, 4e+08 Hz, needs 1
    >>> try:
    ...     check_substeps([rec] * 30_000, 20, None)
    ... except ValueError as exc:
    ...     print(exc)
    identify's search of 3000000 samples runs 20 integration steps a sample (6e+07 in all): \
more than 5e+07; give shorter records
    """
    from motionhyst.core.budget import check_memory

    n = sum(rec.u.size for rec in records) * int(substeps)
    if f_n is None:
        what = (f"identify's search of {sum(rec.u.size for rec in records)} samples runs "
                f"{substeps} integration steps a sample ({n:.3g} in all)")
        remedy = "give shorter records"
    else:
        what = (f"the start's fastest mode, {f_n:.3g} Hz, needs {substeps} integration steps "
                f"per sample of {records[0].fs:.3g} Hz ({n:.3g} in all)")
        remedy = ("the records may not show that stage (a single mass fitted as two masses: "
                  "try --plant mass-spring-damper)")
    if n > MAX_FINE_SAMPLES:
        raise ValueError(f"{what}: more than {MAX_FINE_SAMPLES:.0e}; {remedy}")
    if f_n is not None and not sized:  # the search's own estimate sizes the rest
        check_memory(8.0 * factor * n * 4, what, remedy)


JACOBIAN_COPIES = 6
"""Arrays of samples x parameters a search holds at once at most: its Jacobian, the problem's
assembly of it (the sensitivities, the offsets' and initial states' columns), the trust-region
solver's scaled and augmented copy, the SVD's own copy and left singular vectors."""

RESIDUAL_BYTES = 32
"""Bytes per sample of a run's residuals besides the run (the records' outputs joined, scaled,
cleaned of non-finite values, differenced): a Jacobian column by forward differences."""


def search_memory(records: list[IORecord], substeps: int, parameters: int, sensitivities: int,
                  *, periodic: bool = False, drift: bool = False, states: int = 0,
                  threads: int | None = None, segments: bool = False) -> dict[str, float]:
    """Bytes an input-output search of the records needs at once at most, by what holds them.

    The search holds each record's upsampled force (and, for a drifting force offset, the
    upsampled time stamps) once; a model evaluation runs the records in parallel threads,
    each holding a block of its fine force (:func:`~motionhyst.time.resample.held_nodes`, at
    :data:`~motionhyst.time.openloop.FINE_BYTES` a node) and, as
    :meth:`~motionhyst.time.openloop.OpenLoop.simulate` estimates its runs,
    :data:`~motionhyst.time.openloop.SAMPLE_BYTES` a sample, with its `sensitivities`
    columns (a link without them: the Jacobian's columns by forward differences, one
    evaluation per thread, as many at once as there are threads and columns, with their
    residuals); the Jacobian of all samples x
    `parameters` is held :data:`JACOBIAN_COPIES` times.  With `segments`, a search on an
    axis (and its rigid slider's) also runs on the records cut into segments
    (:func:`~motionhyst.identify.io_records.segment_records`), each with its own position offset
    and initial velocity: that stage's force, runs and Jacobian (its samples x `parameters`
    and two columns a segment) count where they are larger.

    Parameters
    ----------
    records : list of IORecord
        The records.
    substeps : int
        Integration steps per sample.
    parameters : int
        The search's variables (the Jacobian's columns).
    sensitivities : int
        Columns of the runs' sensitivities (the plant's and the link's parameters).
    periodic : bool
        Records of whole periods (a run holds its period's fine force whole, and the
        sensitivities to its `states` start states).
    drift : bool
        A drifting force offset is estimated.
    states : int
        A periodic run's start states (Newton's steps on the period map; 0: none).
    threads : int, optional
        Threads of the evaluations (default: the machine's cores).
    segments : bool
        The search also runs on the records' segments (on a floating stage, each record's
        position offset and initial velocity estimated).

    Returns
    -------
    dict
        ``force``, ``runs``, ``jacobian`` and their ``total`` [bytes].

    Examples
    --------
    >>> import numpy as np
    >>> n = 1_000_000
    >>> rec = IORecord(np.arange(n) / 1e3, np.zeros(n), np.zeros(n))
    >>> need = search_memory([rec], 20, 7, 4, threads=2)
    >>> {k: round(v / 1e6) for k, v in need.items()}
    {'force': 160, 'runs': 393, 'jacobian': 336, 'total': 889}
    >>> round(search_memory([rec], 20, 7, 4, threads=64)["total"] / 1e6)   # 7 columns at once
    1873
    >>> rec = IORecord(np.arange(20_000) / 1e3, np.zeros(20_000), np.zeros(20_000))
    >>> need = search_memory([rec], 20, 7, 4, threads=2, segments=True)  # 32 segments
    >>> {k: round(v / 1e6) for k, v in need.items()}
    {'force': 6, 'runs': 42, 'jacobian': 55, 'total': 103}
    """
    from motionhyst.time.openloop import FINE_BYTES, SAMPLE_BYTES
    from motionhyst.time.resample import held_nodes

    r = int(substeps)
    n_all = sum(rec.u.size for rec in records)
    threads = max(int(threads or os.cpu_count() or 1), 1)
    parallel = min(len(records), threads)  # the records of one evaluation in parallel
    force = 8.0 * (2 if drift else 1) * sum(r * (rec.u.size - 1) + 1 for rec in records)
    block = max(FINE_BYTES * (r * rec.u.size if periodic else held_nodes(rec.u, r))
                for rec in records)
    per_sample = SAMPLE_BYTES + 16 * states
    # with the sensitivities: one evaluation; without: one for each column in parallel
    exact = parallel * block + (per_sample + 8.0 * sensitivities) * n_all
    columns = min(threads, int(parameters))  # the differences' pool: a column a thread
    differences = columns * (parallel * block + (per_sample + RESIDUAL_BYTES) * n_all)
    runs = float(max(exact, differences))
    jacobian = JACOBIAN_COPIES * 8.0 * n_all * parameters
    parts = [part for _, part in segment_records(records)] if segments else records
    if len(parts) > len(records):  # the segments' search: runs of a segment, one a thread
        n_cut = sum(rec.u.size for rec in parts)
        force += 8.0 * (2 if drift else 1) * sum(r * (rec.u.size - 1) + 1 for rec in parts)
        runs = max(runs, threads * max(FINE_BYTES * held_nodes(rec.u, r) + (
            per_sample + 8.0 * sensitivities + RESIDUAL_BYTES) * rec.u.size for rec in parts))
        jacobian = max(jacobian, JACOBIAN_COPIES * 8.0 * n_cut * (parameters + 2 * len(parts)))
    return {"force": force, "runs": runs, "jacobian": jacobian,
            "total": force + runs + jacobian}


def check_search_memory(records: list[IORecord], substeps: int, parameters: int,
                        sensitivities: int, **kwargs) -> None:
    """Refuse an input-output search above the memory budget before it starts
    (:func:`search_memory`; :func:`motionhyst.core.budget.check_memory`).

    Parameters
    ----------
    records, substeps, parameters, sensitivities
        As for :func:`search_memory`.
    **kwargs
        Its keywords.

    Raises
    ------
    BudgetError
        One line: the search, what it needs and what takes it, the remedy.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.core.budget import BudgetError, set_max_memory
    >>> rec = IORecord(np.arange(1000) / 1e3, np.zeros(1000), np.zeros(1000))
    >>> set_max_memory(1 << 20)
    >>> try:
    ...     check_search_memory([rec] * 3, 20, 7, 4, threads=2)
    ... except BudgetError as exc:
    ...     print(exc)
    identify's search of 3000 samples (20 integration steps each, 7 parameters) needs \
5.9 MB, above the memory budget of 1.05 MB (--max-memory); its runs take 4.41 MB, its \
Jacobian's copies 1.01 MB, the upsampled force 480 kB: a larger --max-memory if the machine \
has it, or shorter records
    >>> set_max_memory(None)
    """
    from motionhyst.core.budget import check_memory, format_size

    need = search_memory(records, substeps, parameters, sensitivities, **kwargs)
    n_all = sum(rec.u.size for rec in records)
    parts = sorted(((need["runs"], "its runs"), (need["jacobian"], "its Jacobian's copies"),
                    (need["force"], "the upsampled force")), reverse=True)
    takes = ", ".join(f"{name} {format_size(size) if i else 'take ' + format_size(size)}"
                      for i, (size, name) in enumerate(parts))
    check_memory(need["total"],
                 f"identify's search of {n_all} samples ({int(substeps)} integration steps "
                 f"each, {parameters} parameters)",
                 f"{takes}: a larger --max-memory if the machine has it, or shorter records")


def extras_start(extras: Extras, records, floating: bool, u0: float) -> NDArray[np.float64]:
    """Start values of the offsets and initial states: the force offset `u0`, a floating
    stage's position offset at the record's first sample (else 0), its initial position
    there and its velocity at the first samples' slope."""
    out = np.zeros(extras.size)
    if extras.input_offset:
        out[0] = u0
    what = (["output_offset"] if extras.output_offset else []) + list(extras.initial)
    for i, rec in enumerate(records):
        n = min(4, rec.y.size - 1)
        start = {"v0": (rec.y[n] - rec.y[0]) * rec.fs / n, "y0": rec.y[0],
                 "output_offset": rec.y[0] if floating else 0.0}
        for j, name in zip(extras.columns_of_record(i), what, strict=True):
            out[j] = start[name]
    return out
