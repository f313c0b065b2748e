"""Grey-box identification of a stage and its link from input-output records.

The records are force ``u`` in, position ``y`` out (the link force is not
measured), each an experiment from rest or, with ``periodic=True``, whole
periods of a periodic steady state.  The plant (a :class:`MassSpringDamper`,
or the floating two-mass stage of eqs. (1)-(2), :class:`~motionhyst.openloop.TwoMass`,
with ``y2`` or ``y1`` measured) and the link are estimated jointly by
minimising the *simulation* error

.. math::

    V(\\theta) = \\sum_{records} \\sum_i \\left(\\hat y_i(\\theta; u) - y_i\\right)^2,

the model being run from the input alone (:class:`~motionhyst.openloop.OpenLoop`),
as the Bouc-Wen benchmark scores it (Noel and Schoukens 2016).

Method
------
1. Start, plant: the best linear approximation ``1 / (m s^2 + c s + k)`` fitted
   to the records' frequency response ``G = sum Y U* / sum |U|^2`` at the lines
   carrying input power (weighted by ``|G|``, i.e. the relative output error).
2. Start, link: the linear fit by simulation error; then the link's force is
   introduced by splitting the best linear stiffness ``k`` between the stage
   and the link (Bouc-Wen: ``alpha`` split from ``k`` or added to it, a grid
   of ``beta*gamma`` and ``delta/gamma``, each start screened by one
   simulation, see :func:`_bouc_wen_starts`; the full refinement runs from
   the best start, or the next when it ends outside the model's accepted
   set; the
   other links, from the model registry: parameters started by their units,
   the link slipping within the records or hardly at all, a rate scale such
   as LuGre's ``vs`` held on a grid, see :func:`_identify_elements`).  Several
   starts are refined on a short part of the records and the best continues.
   The two-mass stage: :func:`best_linear_approximation_two_mass` (the link a
   spring and damper to the ground; from rest, the frequency response of an
   ARX model of the records), then the link's initial stiffness 1, 3 and 9
   times that spring with mild to strong nonlinearity, then three splits of
   the mass at the same internal mode (see :func:`_two_mass_start`); its
   element links from 1, 4 and 16 times that spring and forces of 0.3 to 3
   times the force's RMS (see :func:`_identify_elements`).
3. Refinement: :func:`scipy.optimize.least_squares` (trust-region reflective)
   on parameters scaled by their start values.  Bouc-Wen: the exact Jacobian
   from forward sensitivities integrated with the model (RK4); other links:
   the exact Jacobian from the forward sensitivities of their simulation, on
   either plant (:func:`~motionhyst.openloop.simulate_elements`; finite differences,
   columns in parallel threads, for an element kind without them).  Stopping rule:
   the first of a relative cost reduction below ``ftol``, a relative step below ``xtol`` or a scaled
   gradient below ``gtol`` (all ``1e-12`` by default), or ``max_nfev``
   evaluations.
4. Standard errors ``sqrt(diag(sigma^2 (J^T J)^-1))``, ``sigma^2 = RSS/(N - p)``,
   from the scaled Jacobian's singular values: a direction whose singular
   value is below ``1e-8`` of the largest (``1e-5`` for a finite-difference
   Jacobian) is not determined by the data; its parameters are reported as
   not identifiable, with the others they combine with (never as a huge
   standard error), and the rest from the pseudo-inverse.  Other links also
   report a parameter whose standard error exceeds its value (with the
   parameters its estimate is correlated with), a rate scale whose profile is
   flat (95 % likelihood ratio), and a parameter that only adds a spring or
   damper in parallel with the stage's (``Parameter.parallel``, e.g. LuGre's
   ``sigma2``: only ``c + sigma2`` enters the output; fixed at 0).

The benchmark's Bouc-Wen parameters ``beta, gamma, delta`` enter the model only
as ``beta*gamma`` and ``beta*delta`` (``z`` is not measured and ``beta`` always
multiplies ``gamma`` or ``delta``), so those products are what is estimated;
``beta`` itself is not identifiable and is fixed by the normalisation
``|gamma| + |delta| = 1`` in the returned model.
"""

from __future__ import annotations

import math
import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from motionhyst.hysteresis import MODELS as REGISTERED
from motionhyst.hysteresis import BoucWen, Hysteresis, Parameter
from motionhyst.openloop import (
    MIN_SUBSTEPS,
    STEPS_PER_MODE_PERIOD,
    MassSpringDamper,
    OpenLoop,
    TwoMass,
    check_record,
    fine_input,
    is_periodic_record,
    sampling_rate,
    simulate_bouc_wen,
    simulate_elements,
)

MIN_SAMPLES = 64
#: Link models for input-output records: Bouc-Wen (exact sensitivities) and every other
#: registered model (its parameters taken from the registry); not maxwell-iwan, whose Iwan
#: element of 256 stop operators makes a simulation too slow for a search
MODELS = ("bouc-wen", *(name for name in REGISTERED if name not in ("bouc-wen",
                                                                      "maxwell-iwan")))
PLANTS = ("mass-spring-damper", "two-mass")
BLA_STARTS = 6  # two-mass: grid points refined
SINGULAR_RTOL = 1e-8
FD_SINGULAR_RTOL = 1e-5  # finite-difference Jacobians (step 1e-6) are no more exact than this


@dataclass
class IORecord:
    """One input-output record: time [s], force [N], displacement [m] and a name."""

    t: NDArray[np.float64]
    u: NDArray[np.float64]
    y: NDArray[np.float64]
    name: str = "record"

    @property
    def fs(self) -> float:
        """Sampling frequency [Hz]."""
        return sampling_rate(self.t)


def load_io_csv(path: str | Path) -> IORecord:
    """Read a record with columns ``time,force,displacement`` (one-line ``ValueError``)."""
    from motionhyst.csvdata import read_columns

    data = read_columns(path, ("time", "force", "displacement"))
    return IORecord(data[:, 0], data[:, 1], data[:, 2], str(path))


def check_records(records: list[IORecord], periodic: bool) -> list[IORecord]:
    """Validate records; raises ``ValueError`` with one line naming the record."""
    if not records:
        raise ValueError("no records")
    out = []
    for rec in records:
        t = np.asarray(rec.t, dtype=float)
        u = np.asarray(rec.u, dtype=float)
        y = np.asarray(rec.y, dtype=float)
        if not (t.shape == u.shape == y.shape) or t.ndim != 1:
            raise ValueError(f"{rec.name}: time, force and displacement differ in length")
        if t.size < MIN_SAMPLES:
            raise ValueError(f"{rec.name}: too short ({t.size} samples; need at least "
                             f"{MIN_SAMPLES})")
        if not np.all(np.isfinite(y)):
            raise ValueError(f"{rec.name}: displacement is not finite everywhere")
        try:
            check_record(t, u)
        except ValueError as exc:
            raise ValueError(f"{rec.name}: {exc}") from None
        if np.ptp(u) <= 1e-12 * max(1.0, float(np.max(np.abs(u)))):
            raise ValueError(f"{rec.name}: the force is constant; it excites nothing")
        if np.ptp(y) == 0.0:
            raise ValueError(f"{rec.name}: the displacement is constant")
        out.append(IORecord(t, u, y, rec.name))
    fs = out[0].fs
    for rec in out[1:]:
        if abs(rec.fs - fs) > 1e-9 * fs:
            raise ValueError(f"{rec.name}: sampled at {rec.fs:.6g} Hz, {out[0].name} at "
                             f"{fs:.6g} Hz; records must share one sampling rate")
    return out


# ----------------------------------------------------------------- the best linear approximation
def best_linear_approximation(records: list[IORecord]) -> MassSpringDamper:
    """``m, c, k`` of ``1 / (m s^2 + c s + k)`` fitted to the records' frequency response.

    ``G(f) = sum Y U* / sum |U|^2`` over the records (each transformed whole),
    at the lines whose input power is at least ``1e-3`` of the largest; the
    fit minimises ``sum |G| ^2 |1/G - (k - m w^2 + j c w)|^2``.  Negative
    estimates are clipped to small positive values (a start, not a result).

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.openloop import MassSpringDamper, OpenLoop
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


def two_mass_response(theta: NDArray[np.float64], f_hz: NDArray[np.float64], output: str
                      ) -> NDArray[np.complex128]:
    """``y2 / u`` or ``y1 / u`` of the two-mass stage (eqs. 1-2) held by a spring ``kl``
    and damper ``cl`` on ``y1``; ``theta = (m1, m2, b, k, kl, cl)``.

    With ``D = (m1 s^2 + (b + cl) s + k + kl)(m2 s^2 + b s + k) - (b s + k)^2``:
    ``y2 / u = (b s + k) / D`` and ``y1 / u = (m2 s^2 + b s + k) / D``.
    """
    m1, m2, b, k, kl, cl = theta
    s = 2j * np.pi * f_hz
    inner = b * s + k
    D = (m1 * s * s + (b + cl) * s + k + kl) * (m2 * s * s + inner) - inner * inner
    return (inner if output == "y2" else m2 * s * s + inner) / D


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

    Returns
    -------
    plant : TwoMass
    k_link, c_link : float
        The link's linear stiffness [N/m] and damping [N s/m].

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.openloop import OpenLoop, TwoMass
    >>> from motionhyst.hysteresis import BoucWen
    >>> t = np.arange(4096) / 750
    >>> u = np.random.default_rng(0).standard_normal(4096)
    >>> spring = BoucWen.from_general(5e4, 1.0, 0.0, 0.0, 1.0)   # beta = 0: a spring
    >>> y = OpenLoop(TwoMass(2.0, 3.0, 20.0, 2e5), spring).simulate(t, u, periodic=True)
    >>> p, kl, cl = best_linear_approximation_two_mass([IORecord(t, u, y.displacement)])
    >>> round(p.m1, 3), round(p.m2, 3), round(p.b, 2), round(p.k), round(kl), round(cl, 6)
    (2.0, 3.0, 20.0, 200000, 50000, 0.0)
    """
    f, G = _spectral_response(records)
    keep = f < 0.5 * records[0].fs * (1 - 1e-9)  # the Nyquist line is ambiguous
    f, G = f[keep], G[keep]
    if not periodic:
        G = _arx_response(records, f)
    s = 2j * np.pi * f
    grid = []
    for om in 2 * np.pi * np.geomspace(0.5 * f[0], 10 * f[-1], 80):
        for zeta in np.geomspace(0.002, 0.5, 12):
            H = (2 * zeta * om * s + om * om) / (s * s + 2 * zeta * om * s + om * om)
            Z = 1.0 / G if output == "y1" else H / G
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
            e = (two_mass_response(np.exp(logt), f, output) - G) / mag
        r = np.concatenate([e.real, e.imag])
        return np.where(np.isfinite(r), r, 1e6)

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
    return TwoMass(m1, m2, b, k, output), float(kl), float(cl)


# ----------------------------------------------------------------- result
@dataclass
class IOIdentification:
    """A plant and link identified from input-output records by simulation error.

    Attributes
    ----------
    plant : MassSpringDamper or TwoMass
    hysteresis : Hysteresis
        The link model (Bouc-Wen in the general form, normalised so that
        ``|gamma| + |delta| = 1``; or Maxwell-slip).
    estimates : dict
        Every estimated parameter (identifiable quantities only) by name.
    std : dict
        Standard error of each estimate (same keys); ``None`` where the data
        do not determine it (then listed in `not_identifiable`).
    not_identifiable : dict
        Parameter name -> why it is not identifiable and what is.
    fit_rms : float
        RMS simulation error over all records [m].
    records : list of dict
        Per record: ``{"name", "samples", "fit_rms", "output_rms"}``.
    seconds : float
        Wall time of the identification [s].
    periodic : bool
        Records taken as steady-state periods (True) or from rest (False).
    stopping : str
        Why the refinement stopped (scipy's message) and its tolerances.
    n_evaluations : int
        Model evaluations of the refinement.
    """

    plant: MassSpringDamper
    hysteresis: Hysteresis
    estimates: dict[str, float]
    std: dict[str, float | None]
    not_identifiable: dict[str, str]
    fit_rms: float
    records: list[dict]
    seconds: float
    periodic: bool
    stopping: str
    n_evaluations: int
    substeps: int = 0
    extra: dict = field(default_factory=dict)

    def system(self) -> OpenLoop:
        """The identified open-loop system."""
        return OpenLoop(self.plant, self.hysteresis)

    def to_dict(self) -> dict:
        """JSON-ready: ``plant``, ``hysteresis``, ``std``, ``fit_rms``, ``records``, ``seconds``."""
        return {"plant": self.plant.to_dict(), "hysteresis": self.hysteresis.to_dict(),
                "estimates": dict(self.estimates), "std": dict(self.std),
                "not_identifiable": dict(self.not_identifiable), "fit_rms": self.fit_rms,
                "records": [dict(r) for r in self.records], "seconds": self.seconds,
                "periodic": self.periodic, "stopping": self.stopping,
                "evaluations": self.n_evaluations, "substeps": self.substeps}

    def scenario_text(self) -> str:
        """A scenario file (TOML) of the identified system: ``[stage]`` and ``[hysteresis]``."""
        lines = [f"# identified from {len(self.records)} input-output record(s) by simulation "
                 f"error: fit RMS {self.fit_rms:.4g} m", "[stage]"]
        for key, value in self.plant.to_dict().items():
            lines.append(f'{key} = "{value}"' if isinstance(value, str)
                         else f"{key} = {_toml(value)}")
        lines.append("")
        lines.append("[hysteresis]")
        for key, value in self.hysteresis.to_dict().items():
            if isinstance(value, str):
                lines.append(f'{key} = "{value}"')
            elif isinstance(value, list | tuple | np.ndarray):
                lines.append(f"{key} = [{', '.join(_toml(v) for v in value)}]")
            else:
                lines.append(f"{key} = {_toml(value)}")
        return "\n".join(lines) + "\n"


def _toml(v: float) -> str:
    s = repr(float(v))
    return s if any(ch in s for ch in ".en") else s + ".0"


# ----------------------------------------------------------------- Bouc-Wen problem
class _BoucWenProblem:
    """Simulation residuals of the stage with a general Bouc-Wen link, and their Jacobian.

    The parameter vector: the plant's first three parameters, ``alpha,
    beta*gamma, beta*delta, nu``, then the plant's others (a two-mass stage's
    ``k``), so that the link's always sit at 3-6.  `plant` gives the kind of
    plant (default: a mass-spring-damper).
    """

    def __init__(self, records: list[IORecord], periodic: bool, substeps: int,
                 free: NDArray[np.bool_], fixed: NDArray[np.float64], y_scale: float,
                 force_scale: float = 1.0, plant: MassSpringDamper | TwoMass | None = None):
        self.y_scale = y_scale  # residuals in units of the output's RMS
        self.plant = plant if plant is not None else MassSpringDamper(1.0, 0.0, 0.0)
        n_plant = len(self.plant.PARAMETERS)
        # problem order -> simulation order (the plant's parameters, then the link's)
        self.order = np.r_[0:3, 7:4 + n_plant, 3:7]
        # a floating stage's periodic output is known up to a constant: compared without means
        self.centre = periodic and isinstance(self.plant, TwoMass)
        # with nu free the products are searched as beta*gamma F^(nu - 1) (and delta): the
        # size of beta*gamma |z|^nu at |z| ~ F, which then does not move with nu
        self.force_scale = force_scale if free[6] else 1.0
        self.records = records
        self.periodic = periodic
        self.r = substeps
        self.free = free
        self.fixed = fixed
        self.fine = [fine_input(rec.u, 2 * substeps, periodic) for rec in records]
        self.n_eval = 0

    def full(self, q_free: NDArray[np.float64], scale: NDArray[np.float64]) -> NDArray:
        """Parameters ``m, c, k, alpha, beta*gamma, beta*delta, nu`` (and a two-mass stage's
        ``k``) of the search variables."""
        p = self.fixed.copy()
        p[self.free] = q_free * scale[self.free]
        if self.force_scale != 1.0:
            p[4:6] *= self.force_scale ** (1.0 - p[6])
        return p

    def variables(self, p: NDArray[np.float64], scale: NDArray[np.float64]) -> NDArray:
        """The search variables of the parameters `p` (inverse of :meth:`full`)."""
        q = p / scale
        if self.force_scale != 1.0:
            q[4:6] /= self.force_scale ** (1.0 - p[6])
        return q[self.free]

    def jacobian(self, dy_dp: NDArray[np.float64], p: NDArray[np.float64],
                 scale: NDArray[np.float64]) -> NDArray:
        """Derivatives in the search variables from those in the parameters (chain rule)."""
        J = dy_dp * scale
        if self.force_scale != 1.0:
            f = self.force_scale ** (1.0 - p[6])
            J[:, 6] -= math.log(self.force_scale) * scale[6] * (dy_dp[:, 4] * p[4]
                                                                 + dy_dp[:, 5] * p[5])
            J[:, 4:6] *= f
        return J[:, self.free]

    def run(self, p: NDArray[np.float64], jac: bool):
        self.n_eval += 1
        def one(i):
            rec = self.records[i]
            try:
                y, s = simulate_bouc_wen(p[self.order], rec.u, rec.fs, self.r,
                                         periodic=self.periodic, sensitivities=jac,
                                         upsampled=self.fine[i], plant=self.plant)
            except ValueError:  # no periodic steady state: a point the search must leave
                return np.full(rec.u.size, np.nan), np.zeros((rec.u.size, p.size))
            if jac:
                s_problem = np.empty_like(s)
                s_problem[:, self.order] = s
                s = s_problem
            return y, s

        if len(self.records) > 1:  # the compiled runs release the GIL: one thread per record
            with ThreadPoolExecutor(max_workers=min(len(self.records), os.cpu_count() or 1)
                                    ) as pool:
                outs = list(pool.map(one, range(len(self.records))))
        else:
            outs = [one(0)]
        res = [y - (rec.y - np.mean(rec.y) if self.centre else rec.y)
               for (y, _), rec in zip(outs, self.records, strict=True)]
        rows = [s for _, s in outs]
        r = np.concatenate(res) / self.y_scale
        if not np.all(np.isfinite(r)):
            r = np.full_like(r, 1e3)
        return r, (np.concatenate(rows) / self.y_scale if jac else None)


def _solve(prob: _BoucWenProblem, p0: NDArray[np.float64], scale: NDArray[np.float64],
           tol: float, max_nfev: int):
    """Trust-region refinement of the free parameters (m > 0; c, k, alpha >= 0; nu >= 1)."""
    cache: dict = {}

    # the sensitivities cost ~40 % of a run and are needed at every accepted point:
    # computed with every residual, kept for the Jacobian of the same point
    def evaluate(q):
        key = q.tobytes()
        hit = cache.get(key)
        if hit is not None:
            return hit
        p = prob.full(q, scale)
        r, s = prob.run(p, True)
        cache.clear()
        cache[key] = (r, s, p)
        return r, s, p

    def fun(q):
        return evaluate(q)[0]

    def jacobian(q):
        _, s, p = evaluate(q)
        return prob.jacobian(s, p, scale)

    q0 = prob.variables(p0, scale)
    # m > 0 and c, k, alpha >= 0 (a stage and link that exist), nu >= 1
    low = np.array([1e-6, 0.0, 0.0, 0.0, -np.inf, -np.inf, 1.0 / scale[6]])
    if prob.fixed.size > 7:  # a two-mass stage (m1, m2, b, ..., k): m1, m2, k > 0, b >= 0
        low = np.array([1e-6, 1e-6, 0.0, 0.0, -np.inf, -np.inf, 1.0 / scale[6], 1e-6])
    lower = low[prob.free]
    q0 = np.where(np.isfinite(lower), np.maximum(q0, lower + 1e-9 * np.abs(q0) + 1e-12), q0)
    sol = least_squares(fun, q0, jac=jacobian, method="trf", x_scale=1.0, ftol=tol, xtol=tol,
                        gtol=tol, max_nfev=max_nfev, bounds=(lower, np.inf))
    return sol


def _force_scale(p: NDArray[np.float64], y_scale: float) -> float:
    """A typical link force ``|z|`` [N]: ``alpha y_scale``, or the ultimate force if smaller."""
    alpha, b, nu = p[3], p[4] + p[5], p[6]
    f = abs(alpha) * y_scale
    if b > 0.0 and alpha > 0.0:
        f = min(f, (alpha / b) ** (1.0 / nu))
    return f if math.isfinite(f) and f > 0.0 else 1.0


def _uncertainty(J: NDArray[np.float64], rss: float, n_rows: int,
                 rtol: float = SINGULAR_RTOL
                 ) -> tuple[NDArray[np.float64], list[list[int]]]:
    """Standard errors of the parameters and the groups the data cannot separate.

    The columns of `J` are normalised; a right singular vector whose singular
    value is below `rtol` of the largest is a direction the data do not
    determine, and the parameters with a component above 1e-3 in it form a
    group (only other combinations of them are determined).  Their standard
    errors are NaN; the others come from the pseudo-inverse.
    """
    norms = np.linalg.norm(J, axis=0)
    norms[norms == 0] = 1.0
    Jn = J / norms
    _, sv, vt = np.linalg.svd(Jn, full_matrices=False)
    p = J.shape[1]
    sigma2 = rss / max(n_rows - p, 1)
    good = sv > rtol * sv[0]
    groups = [list(np.nonzero(np.abs(vt[i]) > 1e-3)[0]) for i in np.nonzero(~good)[0]]
    cov = (vt[good].T / sv[good] ** 2) @ vt[good]
    std = np.sqrt(sigma2 * np.diag(cov)) / norms
    for g in groups:
        std[g] = np.nan
    return std, groups


def _undetermined_notes(names: list[str], groups: list[list[int]], rtol: float
                        ) -> dict[str, str]:
    notes: dict[str, str] = {}
    for g in groups:
        members = [names[i] for i in g]
        for i in g:
            others = [m for m in members if m != names[i]]
            what = (f"only a combination with {', '.join(others)} is" if others
                    else "it has no effect on the output")
            notes[names[i]] = (f"not determined by these records: {what} (a direction of "
                               f"the Jacobian with a singular value below {rtol:g} of the "
                               f"largest)")
    return notes


def _correlation(J: NDArray[np.float64], rtol: float) -> NDArray[np.float64]:
    """Correlation matrix of the estimates, ``(J^T J)^+`` over the determined directions."""
    norms = np.linalg.norm(J, axis=0)
    norms[norms == 0] = 1.0
    _, sv, vt = np.linalg.svd(J / norms, full_matrices=False)
    good = sv > rtol * sv[0]
    cov = (vt[good].T / sv[good] ** 2) @ vt[good]
    d = np.sqrt(np.maximum(np.diag(cov), 1e-300))
    return cov / np.outer(d, d)


def _weak_notes(names: list[str], values: NDArray[np.float64], std: NDArray[np.float64],
                J: NDArray[np.float64], rtol: float, may_be_zero: NDArray[np.bool_]
                ) -> dict[str, str]:
    """Parameters whose standard error exceeds their value: not determined by the records.

    A parameter that must be positive is then reported with the parameters its
    estimate is correlated with (``|r| > 0.99``: only that combination is
    determined), or as having almost no effect at the records' noise; one that
    may be zero as not distinguishable from 0.
    """
    corr = _correlation(J, rtol)
    notes: dict[str, str] = {}
    for i, name in enumerate(names):
        s = std[i]
        if not (math.isfinite(s) and s > abs(values[i])):
            continue
        if may_be_zero[i]:
            notes[name] = (f"not distinguishable from 0 by these records (estimate "
                           f"{values[i]:.4g} +- {s:.2g})")
            continue
        partners = [f"{names[j]} (r = {corr[i, j]:+.4f})" for j in range(len(names))
                    if j != i and abs(corr[i, j]) > 0.99]
        what = (f"only a combination with {', '.join(partners)} is" if partners else
                "it has almost no effect on the output at the records' noise")
        notes[name] = (f"not determined by these records: its standard error {s:.2g} exceeds "
                       f"the estimate {values[i]:.4g}; {what}")
    return notes


def identify_io(records: list[IORecord], model: str = "bouc-wen", *, periodic: bool = False,
                nu: float | None = 1.0, substeps: int | None = None, tol: float = 1e-12,
                max_nfev: int = 60, n_elements: int = 4, start_nfev: int | None = None,
                plant: str = "mass-spring-damper", output: str = "y2") -> IOIdentification:
    """Identify a stage and its link from input-output records.

    Parameters
    ----------
    records : list of IORecord
        Force in, displacement out; each from rest (``y = y' = 0``, link relaxed
        at the first sample) or, with `periodic`, whole periods of a steady state.
    model : str
        The link's model, one of :data:`MODELS` (``"bouc-wen"``, ``"jenkins"``,
        ``"maxwell-slip"``, ``"dahl"``, ``"lugre"``): Bouc-Wen with exact
        sensitivities, the others from the model registry (LuGre's viscous
        ``sigma2`` is not estimated: it adds to ``c``).
    periodic : bool
        Records are steady-state periods (each record one period or several
        whole periods of its force).  A floating stage's (the two-mass one) is
        known up to a constant position: records and model are compared with
        their means removed.
    plant : {"mass-spring-damper", "two-mass"}
        The stage: :class:`~motionhyst.openloop.MassSpringDamper` (``m, c, k``)
        or the floating :class:`~motionhyst.openloop.TwoMass` of eqs. (1)-(2)
        (``m1, m2, b, k``; the force and the link on ``m1``, no spring to the
        ground but the link's).
    output : {"y2", "y1"}
        Two-mass stage: the measured position (``y2``, the point of control, or
        ``y1``, the actuated mass).
    nu : float or None
        Bouc-Wen exponent: fixed at this value, or estimated (``nu >= 1``) when
        None, starting from 1.  With ``nu`` free the products ``beta*gamma`` and
        ``beta*delta`` change units with it (``N^(1-nu)/m``), and searched as they
        are they crawl along a long valley with ``nu``; the search therefore takes
        ``beta*gamma F^(nu-1)`` and ``beta*delta F^(nu-1)`` (the size of the
        nonlinear terms at a typical link force ``F``: ``alpha`` times the
        output's RMS, or the ultimate force if smaller), which do not move with
        ``nu``; the sensitivities follow by the chain rule.  The estimates are
        still ``beta*gamma`` and ``beta*delta`` at the estimated ``nu``.
    n_elements : int
        Maxwell-slip: number of Jenkins elements.
    start_nfev : int, optional
        Links other than Bouc-Wen: evaluations of each start's refinement on the
        short part of the records (default ``15 p``, ``p`` parameters).
    substeps : int, optional
        Integration steps per sample (default: the model's
        :meth:`~motionhyst.openloop.OpenLoop.default_substeps` at the start).
    tol : float
        ``ftol = xtol = gtol`` of the refinement.
    max_nfev : int
        Largest number of model evaluations of the refinement.

    Returns
    -------
    IOIdentification

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.openloop import MassSpringDamper, OpenLoop
    >>> from motionhyst.hysteresis import BoucWen
    >>> true = OpenLoop(MassSpringDamper(2.0, 10.0, 5e4), BoucWen(k=5e4, fc=20.0, beta=0.6,
    ...                                                            gamma=0.2))
    >>> t = np.arange(1024) / 750
    >>> u = 40 * np.sin(2 * np.pi * 8 * t) + 20 * np.sin(2 * np.pi * 31 * t)
    >>> y = true.simulate(t, u).displacement
    >>> fit = identify_io([IORecord(t, u, y)])
    >>> round(fit.plant.m, 6), round(fit.estimates["alpha"])
    (2.0, 50000)
    """
    t_start = time.perf_counter()
    if model not in MODELS:
        raise ValueError(f"unknown link model {model!r} for input-output records; expected one "
                         f"of {', '.join(MODELS)}")
    records = check_records(list(records), periodic)
    if periodic:
        for rec in records:
            rec_period = is_periodic_record(rec.u)
            if rec_period is None and abs(rec.u[0] - rec.u[-1]) > 0.5 * np.ptp(rec.u):
                raise ValueError(f"{rec.name}: periodic records must hold whole periods of "
                                 f"the force; its ends do not join")
    if plant not in PLANTS:
        raise ValueError(f"unknown plant {plant!r} for input-output records; expected one of "
                         f"{', '.join(PLANTS)}")
    if output not in TwoMass.OUTPUTS:
        raise ValueError(f"unknown output {output!r}; expected y2 or y1")
    if model != "bouc-wen":
        return _identify_elements(records, model, periodic, substeps, tol, max_nfev,
                                  n_elements, t_start, start_nfev, plant, output)
    if plant == "two-mass":
        return _identify_two_mass(records, periodic, nu, substeps, tol, max_nfev, output,
                                  t_start)
    bla = best_linear_approximation(records)
    fs = records[0].fs
    r = substeps or OpenLoop(bla).default_substeps(fs)
    y_scale = float(np.sqrt(np.mean(np.concatenate([rec.y for rec in records]) ** 2)))
    # scales: m, c, k from the BLA; alpha like k; the products like 1 / y_scale; nu 1
    scale = np.array([bla.m, max(bla.c, 1e-3 * bla.m), bla.k, bla.k, 1.0 / y_scale,
                      1.0 / y_scale, 1.0])
    free = np.array([True] * 6 + [nu is None])
    nu0 = 1.0 if nu is None else float(nu)

    # 1. the linear model by simulation error (link off), on a short part of the records
    short = _short_records(records, periodic)
    lin_free = np.array([True, True, True, False, False, False, False])
    prob = _BoucWenProblem(short, periodic, r, lin_free,
                           np.array([bla.m, bla.c, bla.k, 0.0, 0.0, 0.0, nu0]), y_scale)
    sol = _solve(prob, prob.fixed, scale, 1e-10, 30)
    lin = prob.full(sol.x, scale)
    n_eval = prob.n_eval

    # 2. starts (nu at its start value; a free nu joins in the refinement): each simulated
    # once on the short part of the records; the basic ones and the best others refined there
    free_start = free.copy()
    free_start[6] = False
    sp = _BoucWenProblem(short, periodic, r, free_start, lin, y_scale)
    screened = []
    for i, p0 in enumerate(_bouc_wen_starts(lin, y_scale, nu0)):
        res, _ = sp.run(p0, False)
        screened.append((float(res @ res), i, p0))
    n_eval += sp.n_eval
    screened.sort(key=lambda c: c[:2])
    chosen = [c for c in screened if c[1] < len(BASIC_STARTS)]
    chosen += [c for c in screened if c[1] >= len(BASIC_STARTS)][:START_REFINED]
    refined = []
    for _, _, p0 in chosen:
        sp = _BoucWenProblem(short, periodic, r, free_start, p0, y_scale)
        s = _solve(sp, p0, scale, 1e-6, 12)
        n_eval += sp.n_eval
        refined.append((float(s.cost), len(refined), sp.full(s.x, scale)))
    refined.sort(key=lambda c: c[:2])
    # 3. refinement on all records, from the best start whose result is a valid system
    error = None
    for _, _, p_start in refined[:FINAL_ATTEMPTS]:
        p, free_used, sol, res, std_q, groups, notes, n = _refine(
            records, periodic, r, free, p_start, y_scale, scale, tol, max_nfev)
        n_eval += n
        try:
            link = _bouc_wen_link(p[3], p[4], p[5], p[6])
            plant = MassSpringDamper(p[0], p[1], p[2])
        except ValueError as exc:
            error = error or exc
            continue
        break
    else:
        raise error
    free = free_used
    rss = float(res @ res)
    names = ["m", "c", "k", "alpha", "beta*gamma", "beta*delta", "nu"]
    free_names = [n for n, f in zip(names, free, strict=True) if f]
    estimates = {n: float(v) for n, v in zip(names, p, strict=True) if n in free_names}
    std: dict[str, float | None] = {}
    not_ident = {"beta": "only the products beta*gamma and beta*delta enter the model "
                         "(z is not measured); beta is fixed by |gamma| + |delta| = 1",
                 "gamma": "see beta", "delta": "see beta", **notes}
    for n, s in zip(free_names, std_q, strict=True):
        std[n] = float(s) if math.isfinite(s) else None
    not_ident.update(_undetermined_notes(free_names, groups, SINGULAR_RTOL))
    per_record = _per_record(records, res)
    return IOIdentification(
        plant=plant, hysteresis=link, estimates=estimates, std=std,
        not_identifiable=not_ident, fit_rms=float(np.sqrt(rss / res.size)),
        records=per_record, seconds=time.perf_counter() - t_start, periodic=periodic,
        stopping=f"{sol.message} (ftol = xtol = gtol = {tol:g}, at most {max_nfev} "
                 f"evaluations; {sol.nfev} used)",
        n_evaluations=n_eval, substeps=r)


#: Starts of the Bouc-Wen link, screened by one simulation each: the link's initial
#: stiffness ``alpha`` as a share of the linear model's stiffness ``k``, taken from the
#: stage's (``split``) or added to it (a link that saturates early hardly shows in ``k``);
#: ``beta*gamma`` in units of 1/output-RMS; ``delta/gamma``: no ultimate force on loading
#: (-1), an ultimate force ``alpha/(beta*gamma)`` (0), or an in-between (-0.5)
START_SHARES = (0.25, 0.5, 0.75)
START_PRODUCTS = (0.5, 2.0, 8.0, 32.0)
START_RATIOS = (-1.0, -0.5, 0.0)
#: The starts always refined on the short part of the records (share, beta*gamma in units
#: of 1/output-RMS, delta/gamma = -1), and how many of the other screened starts join them
BASIC_STARTS = tuple((share, lam) for share in START_SHARES for lam in (0.5, 2.0))
START_REFINED = 2
#: Refinements on all records tried, best start first, until one gives a valid link
FINAL_ATTEMPTS = 3


def _bouc_wen_starts(lin: NDArray[np.float64], y_scale: float, nu: float
                     ) -> list[NDArray[np.float64]]:
    """Start parameters ``m, c, k, alpha, beta*gamma, beta*delta, nu`` around the linear fit."""
    starts = [np.array([lin[0], lin[1], (1.0 - share) * lin[2], share * lin[2], lam / y_scale,
                        -lam / y_scale, nu]) for share, lam in BASIC_STARTS]
    for share in START_SHARES:
        for split in (True, False):
            k = (1.0 - share) * lin[2] if split else lin[2]
            for lam in START_PRODUCTS:
                for ratio in START_RATIOS:
                    if split and ratio == -1.0 and lam in (0.5, 2.0):
                        continue  # a basic start
                    starts.append(np.array([lin[0], lin[1], k, share * lin[2], lam / y_scale,
                                            ratio * lam / y_scale, nu]))
    return starts


def _refine(records, periodic, r, free, p, y_scale, scale, tol, max_nfev, plant=None):
    """Refinement on all records; with ``nu`` free and no ultimate force, ``nu = 1`` if the
    data cannot tell it from 1 (the only ``nu`` such links are admitted for)."""
    notes: dict[str, str] = {}
    n_eval = 0
    while True:
        prob = _BoucWenProblem(records, periodic, r, free, p, y_scale,
                               _force_scale(p, y_scale), plant=plant)
        sol = _solve(prob, p, scale, tol, max_nfev)
        n_eval += prob.n_eval
        p = prob.full(sol.x, scale)
        res, jac = prob.run(p, True)
        res *= y_scale
        std_q, groups = _uncertainty(jac[:, free] * y_scale, float(res @ res), res.size)
        if not free[6] or p[4] + p[5] >= 0.0:
            break
        nu_std = std_q[int(np.count_nonzero(free[:6]))]
        if not abs(p[6] - 1.0) <= max(3.0 * nu_std, 1e-9):
            break
        notes["nu"] = (f"not distinguishable from 1 (estimate {p[6]:.9g} +- {nu_std:.2g}); "
                       f"fixed at 1, as the link has no ultimate force "
                       f"(beta*(gamma + delta) < 0), admitted for nu = 1 only")
        free = free.copy()
        free[6] = False
        p[6] = 1.0
    return p, free, sol, res, std_q, groups, notes, n_eval


def _identify_two_mass(records, periodic, nu, substeps, tol, max_nfev, output, t_start
                       ) -> IOIdentification:
    """The two-mass stage and a Bouc-Wen link: :func:`_two_mass_start`, then :func:`_refine`
    on all records (problem order ``m1, m2, b, alpha, beta*gamma, beta*delta, nu, k``)."""
    structure, r, y_scale, scale, free, p, n_eval = _two_mass_start(records, periodic, nu,
                                                                   substeps, output)
    p, free, sol, res, std_q, groups, notes, n = _refine(
        records, periodic, r, free, p, y_scale, scale, tol, max_nfev, plant=structure)
    n_eval += n
    link = _bouc_wen_link(p[3], p[4], p[5], p[6])
    stage = _two_mass_result(p[0], p[1], p[2], p[7], output)
    rss = float(res @ res)
    names = ["m1", "m2", "b", "alpha", "beta*gamma", "beta*delta", "nu", "k"]
    free_names = [n for n, f in zip(names, free, strict=True) if f]
    values = dict(zip(names, p, strict=True))
    std_of = dict(zip(free_names, std_q, strict=True))
    # the plant's parameters first, then the link's
    order = ["m1", "m2", "b", "k", "alpha", "beta*gamma", "beta*delta", "nu"]
    estimates = {n: float(values[n]) for n in order if n in free_names}
    std: dict[str, float | None] = {n: float(std_of[n]) if math.isfinite(std_of[n]) else None
                                    for n in estimates}
    not_ident = {"beta": "only the products beta*gamma and beta*delta enter the model "
                         "(z is not measured); beta is fixed by |gamma| + |delta| = 1",
                 "gamma": "see beta", "delta": "see beta", **notes}
    not_ident.update(_undetermined_notes(free_names, groups, SINGULAR_RTOL))
    return IOIdentification(
        plant=stage, hysteresis=link, estimates=estimates, std=std,
        not_identifiable=not_ident, fit_rms=float(np.sqrt(rss / res.size)),
        records=_per_record(records, res), seconds=time.perf_counter() - t_start,
        periodic=periodic,
        stopping=f"{sol.message} (ftol = xtol = gtol = {tol:g}, at most {max_nfev} "
                 f"evaluations; {sol.nfev} used)",
        n_evaluations=n_eval, substeps=r)


def _two_mass_start(records: list[IORecord], periodic: bool, nu: float | None,
                    substeps: int | None, output: str):
    """Steps 1-2 for the two-mass stage (problem order ``m1, m2, b, alpha, beta*gamma,
    beta*delta, nu, k``): the linear model with the link a spring ``alpha`` (its only
    hold), then starts with the link's nonlinearity, refined on a short part."""
    bla, k_link, _ = best_linear_approximation_two_mass(records, output, periodic)
    structure = TwoMass(1.0, 1.0, 0.0, 1.0, output)
    fs = records[0].fs
    f_n = bla.mechanics().natural_frequency_hz(k_link)
    r = substeps or max(MIN_SUBSTEPS, math.ceil(STEPS_PER_MODE_PERIOD * f_n / fs))
    y_scale = float(np.sqrt(np.mean(np.concatenate([rec.y - (np.mean(rec.y) if periodic else 0.0)
                                                    for rec in records]) ** 2)))
    mu = bla.m1 * bla.m2 / bla.M
    scale = np.array([bla.m1, bla.m2, max(bla.b, 1e-3 * math.sqrt(bla.k * mu)), k_link,
                      1.0 / y_scale, 1.0 / y_scale, 1.0, bla.k])
    free = np.array([True] * 6 + [nu is None, True])
    nu0 = 1.0 if nu is None else float(nu)
    short = _short_records(records, periodic)
    free_start = free.copy()
    free_start[6] = False
    n_eval = 0
    best = None
    # the link's initial stiffness is above the linear (secant) one, up to an order of
    # magnitude for a link driven into saturation; its nonlinearity neither hardening nor
    # softening (gamma + delta = 0), or softening (delta = 0), mild to strong
    for stiffer in (1.0, 3.0, 9.0):
        for lam_g, lam_d in ((0.5, -0.5), (2.0, -2.0), (8.0, -8.0), (1.0, 0.0), (4.0, 0.0)):
            p0 = np.array([bla.m1, bla.m2, bla.b, stiffer * k_link, lam_g / y_scale,
                           lam_d / y_scale, nu0, bla.k])
            sp = _BoucWenProblem(short, periodic, r, free_start, p0, y_scale,
                                 plant=structure)
            s = _solve(sp, p0, scale, 1e-6, 12)
            n_eval += sp.n_eval
            if best is None or s.cost < best[0]:
                best = (s.cost, sp.full(s.x, scale))
    # the split of the mass is what a linear fit of y2 sees least (and the link's
    # nonlinearity biases): from the best, other splits with the same total mass and
    # internal mode
    m_total = best[1][0] + best[1][1]
    omega2 = best[1][7] * m_total / (best[1][0] * best[1][1])
    for share in (0.25, 0.5, 0.75):
        p0 = best[1].copy()
        p0[0], p0[1] = share * m_total, (1 - share) * m_total
        p0[7] = omega2 * p0[0] * p0[1] / m_total
        sp = _BoucWenProblem(short, periodic, r, free_start, p0, y_scale, plant=structure)
        s = _solve(sp, p0, scale, 1e-6, 12)
        n_eval += sp.n_eval
        if s.cost < best[0]:
            best = (s.cost, sp.full(s.x, scale))
    return structure, r, y_scale, scale, free, best[1], n_eval


def _two_mass_result(m1: float, m2: float, b: float, k: float, output: str) -> TwoMass:
    """The identified two-mass stage (one-line ``ValueError`` for a non-physical one)."""
    try:
        return TwoMass(m1, m2, max(b, 0.0), k, output)
    except ValueError as exc:
        raise ValueError(f"the identified two-mass stage (m1={m1:.6g}, m2={m2:.6g}, b={b:.6g}, "
                         f"k={k:.6g}) is not physical: {exc}") from None


def _per_record(records: list[IORecord], res: NDArray[np.float64]) -> list[dict]:
    out, i = [], 0
    for rec in records:
        e = res[i:i + rec.y.size]
        i += rec.y.size
        out.append({"name": rec.name, "samples": int(rec.y.size),
                    "fit_rms": float(np.sqrt(np.mean(e ** 2))),
                    "output_rms": float(np.sqrt(np.mean(rec.y ** 2)))})
    return out


def _short_records(records: list[IORecord], periodic: bool, n_max: int = 4096
                   ) -> list[IORecord]:
    """The first record, or its first `n_max` samples from rest (whole for periodic records)."""
    rec = records[0]
    if periodic or rec.y.size <= n_max:
        return [rec]
    return [IORecord(rec.t[:n_max], rec.u[:n_max], rec.y[:n_max], rec.name)]


def _bouc_wen_link(alpha: float, bg: float, bd: float, nu: float) -> Hysteresis:
    """The general Bouc-Wen link with ``|gamma| + |delta| = 1`` (``beta`` is not identifiable)."""
    beta = abs(bg) + abs(bd)
    try:
        if beta == 0.0:
            raise ValueError("beta*gamma = beta*delta = 0: the link is a linear spring")
        return BoucWen.from_general(alpha, beta, bg / beta, bd / beta, nu)
    except ValueError as exc:
        raise ValueError(f"the identified Bouc-Wen parameters (alpha={alpha:.6g}, "
                         f"beta*gamma={bg:.6g}, beta*delta={bd:.6g}, nu={nu:.6g}) are outside "
                         f"the model's accepted set: {exc}") from None


# ----------------------------------------------------------------- other links (finite differences)
# start values and search scales by the parameter's unit (registry.Parameter.unit)
_STIFFNESS, _FORCE, _DAMPING, _VELOCITY, _LENGTH = "N/m", "N", "N s/m", "m/s", "m"


@dataclass
class _LinkLayout:
    """How a registered link model's parameters enter the search.

    Built from the model's :class:`~motionhyst.hysteresis.registry.Parameter`
    list alone, so a newly registered model needs no edit here: each value
    (a list parameter gives `n` values) is estimated, as a logarithm when it
    must be positive, linearly (scaled, bounded below by 0) when it may be 0;
    a parameter that only adds a spring or damper in parallel (``parallel``)
    is fixed at 0, since the stage's ``k`` or ``c`` holds the sum.
    """

    model: str
    cls: type
    entries: list[tuple[Parameter, int]]  # (parameter, number of values; -1: a scalar)
    fixed: dict[str, float]

    @classmethod
    def of(cls, model: str, n: int) -> _LinkLayout:
        from motionhyst.hysteresis import model_class

        klass = model_class(model)
        entries, fixed = [], {}
        for par in klass.parameters:
            if par.parallel:
                fixed[par.name] = 0.0
            elif par.many:  # a list: n values (none if the model's default is no element)
                entries.append((par, 0 if par.default == () else n))
            else:
                entries.append((par, -1))
        return cls(model, klass, entries, fixed)

    def _values(self):
        for par, count in self.entries:
            if count < 0:
                yield par, None
            else:
                for i in range(count):
                    yield par, i

    @property
    def names(self) -> list[str]:
        """Names of the estimates, ``link.`` before the model's parameter names."""
        return [f"link.{par.name}" if i is None else f"link.{par.name}[{i}]"
                for par, i in self._values()]

    @property
    def logarithmic(self) -> NDArray[np.bool_]:
        """True for the values searched as logarithms (those that must be positive)."""
        return np.array([par.kind == "positive" for par, _ in self._values()], dtype=bool)

    def build(self, v: NDArray[np.float64]) -> Hysteresis:
        """The link of the values `v` (in the order of :attr:`names`)."""
        kwargs: dict = dict(self.fixed)
        j = 0
        for par, count in self.entries:
            if count < 0:
                kwargs[par.name] = float(v[j])
                j += 1
            else:
                kwargs[par.name] = [float(x) for x in v[j:j + count]]
                j += count
        return self.cls(**kwargs)

    def scales(self, k: float, c: float, y_scale: float, v_scale: float
               ) -> NDArray[np.float64]:
        """Typical magnitude of each value, by its unit (for the linear ones' search)."""
        unit = {_STIFFNESS: k, _FORCE: k * y_scale, _DAMPING: c, _VELOCITY: v_scale,
                _LENGTH: y_scale}
        return np.array([unit.get(par.unit, 1.0) for par, _ in self._values()])

    def start(self, k_link: float, y_scale: float, v_scale: float, c: float,
              slip: float = 1.0) -> NDArray[np.float64]:
        """Start values: stiffness `k_link` slipping across the record's displacement range.

        The stiffness values share `k_link`; element ``i`` of a list slips at a
        displacement from ``0.05`` to ``2`` times `y_scale` (geometric), a
        scalar force at ``0.5 y_scale`` times the link's stiffness (a second
        force half as large again), all times `slip`; a velocity is ``0.1`` of
        `v_scale`, a damping `c`; a parameter with a default starts there.
        """
        values = list(self._values())
        n_stiff = sum(1 for par, _ in values if par.unit == _STIFFNESS)
        k_each = k_link / max(n_stiff, 1)
        n_list = max([count for _, count in self.entries] + [1])
        y_scale = y_scale * slip
        d_list = y_scale * np.geomspace(0.05, 2.0, n_list)
        n_len = sum(1 for par, i in values if par.unit == _LENGTH and i is None)
        d_len = y_scale * np.geomspace(0.05, 2.0, max(n_len, 1))
        out, n_force, j_len = [], 0, 0
        for par, i in values:
            if par.default not in (None, ()) and not par.many:
                out.append(float(par.default))  # type: ignore[arg-type]
            elif par.unit == _STIFFNESS:
                out.append(k_each)
            elif par.unit == _FORCE:
                if i is not None:
                    out.append(k_each * d_list[i])
                else:
                    out.append(k_link * 0.5 * y_scale * 1.5 ** n_force)
                    n_force += 1
            elif par.unit == _LENGTH:
                out.append(d_list[i] if i is not None else d_len[j_len])
                j_len += i is None
            elif par.unit == _VELOCITY:
                out.append(0.1 * v_scale)
            elif par.unit == _DAMPING:
                out.append(c)
            else:
                out.append(1.0)
        return np.array(out)


class _ElementProblem:
    """Simulation residuals of the stage with a link of exact-update elements.

    The search variables are the logarithms of the plant's parameters
    (``m, c, k`` or, with `plant` a :class:`~motionhyst.openloop.TwoMass`,
    ``m1, m2, b, k``) and the link's values, each as a logarithm or scaled
    (see :class:`_LinkLayout`); those not in `free` stay at their values in
    `fixed`.  The Jacobian is exact, from the
    forward sensitivities of the simulation
    (:func:`~motionhyst.openloop.simulate_elements`, computed with the
    residuals), or, for an element kind without them or with `exact` False,
    by forward differences (relative step ``1e-6``), its columns computed in
    parallel.
    """

    def __init__(self, records, periodic, substeps, layout: _LinkLayout, y_scale,
                 scale: NDArray[np.float64], free: NDArray[np.bool_] | None = None,
                 fixed: NDArray[np.float64] | None = None, exact: bool = True,
                 plant: MassSpringDamper | TwoMass | None = None):
        self.records, self.periodic, self.r = records, periodic, substeps
        self.layout, self.y_scale = layout, y_scale
        self.plant = plant if plant is not None else MassSpringDamper(1.0, 0.0, 0.0)
        self.n_plant = len(self.plant.PARAMETERS)
        # a floating stage's periodic output is known up to a constant: compared without means
        self.centre = periodic and isinstance(self.plant, TwoMass)
        self.log = np.concatenate([[True] * self.n_plant, layout.logarithmic])
        self.scale = scale
        self.free = np.ones(self.log.size, bool) if free is None else free
        self.fixed = np.zeros(self.log.size) if fixed is None else fixed
        self.fine = [fine_input(rec.u, substeps, periodic) for rec in records]
        self.n_eval = 0
        self.exact: bool | None = None if exact else False  # sensitivities (None: untried)
        self._last: tuple | None = None

    def values(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """Parameters ``m, c, k, link...`` of the (whole) search vector `q`."""
        return np.where(self.log, np.exp(np.where(self.log, q, 0.0)), q * self.scale)

    def variables(self, v: NDArray[np.float64]) -> NDArray[np.float64]:
        """The whole search vector of the parameters `v`."""
        return np.where(self.log, np.log(np.where(self.log, v, 1.0)), v / self.scale)

    def derivative(self, v: NDArray[np.float64]) -> NDArray[np.float64]:
        """``d v / d q`` of each parameter."""
        return np.where(self.log, v, self.scale)

    def whole(self, q_free: NDArray[np.float64]) -> NDArray[np.float64]:
        """The whole search vector: `q_free` where free, the fixed values elsewhere."""
        q = self.fixed.copy()
        q[self.free] = q_free
        return q

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Lower bound 0 on the linearly searched values, none on the logarithms."""
        lower = np.where(self.log, -np.inf, 0.0)[self.free]
        return lower, np.full(lower.size, np.inf)

    def _run(self, q_free: NDArray[np.float64]) -> NDArray[np.float64]:
        v = self.values(self.whole(q_free))
        try:
            k = self.n_plant
            sys = OpenLoop(self.plant.with_parameters(v[:k]), self.layout.build(v[k:]))
            res = [sys._simulate_elements(rec.u, rec.fs, self.r, self.periodic, fine)
                   - (rec.y - np.mean(rec.y) if self.centre else rec.y)
                   for rec, fine in zip(self.records, self.fine, strict=True)]
            r = np.concatenate(res) / self.y_scale
        except ValueError:
            r = np.full(sum(rec.y.size for rec in self.records), np.nan)
        return np.where(np.isfinite(r), r, 1e3)

    def _run_exact(self, q_free: NDArray[np.float64]
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """Residuals and their exact Jacobian in the free variables (forward sensitivities);
        None if the link has an element kind without them."""
        from motionhyst.identify._element_sensitivities import row_derivatives

        v = self.values(self.whole(q_free))
        n_rows = sum(rec.y.size for rec in self.records)
        k = self.n_plant
        try:
            dparams = row_derivatives(self.layout.build, v[k:])
            if dparams is None:
                return None
            link = self.layout.build(v[k:])
            stepping = link.time_stepping()
            mech = self.plant.mechanics(v[:k])

            def one(i):
                rec = self.records[i]
                return simulate_elements(mech, stepping, rec.u, rec.fs, self.r,
                                         periodic=self.periodic, k_link=link.initial_stiffness,
                                         upsampled=self.fine[i], dparams=dparams)

            if len(self.records) > 1:  # the compiled runs release the GIL
                with ThreadPoolExecutor(max_workers=min(len(self.records),
                                                        os.cpu_count() or 1)) as pool:
                    outs = list(pool.map(one, range(len(self.records))))
            else:
                outs = [one(0)]
            r = np.concatenate([y - (rec.y - np.mean(rec.y) if self.centre else rec.y)
                                for (y, _), rec in zip(outs, self.records, strict=True)])
            J = np.concatenate([sy for _, sy in outs]) * self.derivative(v)
        except ValueError:
            return np.full(n_rows, 1e3), np.zeros((n_rows, int(self.free.sum())))
        r = r / self.y_scale
        if not np.all(np.isfinite(r)) or not np.all(np.isfinite(J)):
            return np.full(n_rows, 1e3), np.zeros((n_rows, int(self.free.sum())))
        return r, J[:, self.free] / self.y_scale

    def residuals(self, q_free: NDArray[np.float64]) -> NDArray[np.float64]:
        """Output errors in units of the output's RMS."""
        self.n_eval += 1
        if self.exact is not False:
            out = self._run_exact(q_free)
            if out is not None:
                self.exact = True
                self._last = (q_free.tobytes(), *out)
                return out[0]
            self.exact = False
        r = self._run(q_free)
        self._last = (q_free.tobytes(), r, None)
        return r

    def jacobian(self, q_free: NDArray[np.float64]) -> NDArray[np.float64]:
        """Exact (forward sensitivities, computed with the residuals), else forward
        differences, one column per free variable, in parallel threads."""
        if self._last is not None and self._last[0] == q_free.tobytes():
            r0, J = self._last[1], self._last[2]
        else:
            r0 = self.residuals(q_free)
            J = self._last[2]
        if J is not None:
            return J
        steps = 1e-6 * np.maximum(1.0, np.abs(q_free))

        def column(j):
            q = q_free.copy()
            q[j] += steps[j]
            return (self._run(q) - r0) / steps[j]

        self.n_eval += q_free.size
        with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
            cols = list(pool.map(column, range(q_free.size)))
        return np.column_stack(cols)

    def solve(self, q0_free: NDArray[np.float64], tol: float, max_nfev: int):
        """Trust-region refinement of the free variables from `q0_free`."""
        return least_squares(self.residuals, q0_free, jac=self.jacobian, method="trf",
                             ftol=tol, xtol=tol, gtol=tol, max_nfev=max_nfev,
                             bounds=self.bounds())


#: The rate scales (velocity parameters, e.g. LuGre's vs) are held at each of these
#: fractions of the records' RMS velocity in turn, the rest refined; the best continues
RATE_GRID = (0.1, 0.01, 0.03, 0.3, 1.0, 3.0)
#: Starts: (stage's and link's stiffness as shares of the best linear one, the link's slip
#: displacements in units of those spanning the records): the link slipping within the
#: records, hardly at all, or early (a stiff link that slips most of the time adds little
#: to the best linear stiffness)
STARTS = ((0.7, 0.3, 1.0), (0.4, 0.6, 1.0), (0.5, 0.5, 10.0), (1.0, 0.5, 0.1))


def _identify_elements(records, model, periodic, substeps, tol, max_nfev, n, t_start,
                       start_nfev, plant="mass-spring-damper", output="y2"
                       ) -> IOIdentification:
    """Stage and a link of exact-update elements by simulation error.

    Starts (on a short part of the records): for the shares of the best linear
    stiffness of stage and link and the slip displacements of
    :data:`STARTS`, the link's values are refined with its
    rate scales (velocities) held at the first of :data:`RATE_GRID`; from the
    better, with the rate scales held at each other value of the grid (a
    profile: the rate scale and the force it shapes form a long valley when
    searched together); the best is refined with everything free on all
    records.

    A two-mass stage (floating: the link is its only hold) starts from
    :func:`best_linear_approximation_two_mass`, the link's stiffness 1, 4 and
    16 times the linear one (its initial stiffness is above that secant one),
    its forces together 0.3, 1 or 3 times the records' force RMS; a parameter
    that adds a spring or damper in parallel is fixed at 0 (the stage has none
    to the ground to hold it).
    """
    layout = _LinkLayout.of(model, n)
    y_all = np.concatenate([rec.y - (np.mean(rec.y) if periodic and plant == "two-mass"
                                     else 0.0) for rec in records])
    y_scale = float(np.sqrt(np.mean(y_all ** 2)))
    v_scale = float(np.sqrt(np.mean(np.concatenate(
        [np.gradient(rec.y, rec.t) for rec in records]) ** 2)))
    force = np.array([par.unit == _FORCE for par, _ in layout._values()], dtype=bool)
    if plant == "two-mass":
        bla, k_link, c_link = best_linear_approximation_two_mass(records, output, periodic)
        structure: MassSpringDamper | TwoMass | None = bla
        f_n = bla.mechanics().natural_frequency_hz(16.0 * k_link)
        r = substeps or max(MIN_SUBSTEPS, math.ceil(STEPS_PER_MODE_PERIOD * f_n
                                                    / records[0].fs))
        mu = bla.m1 * bla.m2 / bla.M
        c_scale = max(c_link, 1e-3 * bla.M * 2 * np.pi * records[0].fs)
        stage0 = [bla.m1, bla.m2, max(bla.b, 1e-3 * math.sqrt(bla.k * mu)), bla.k]
        scale = np.concatenate([stage0, layout.scales(k_link, c_scale, y_scale, v_scale)])
        u_rms = float(np.sqrt(np.mean(np.concatenate([rec.u for rec in records]) ** 2)))
        starts = []
        for stiffer in (1.0, 4.0, 16.0):
            for held_force in (0.3, 1.0, 3.0):
                link0 = layout.start(stiffer * k_link, y_scale, v_scale, c_link)
                if force.any():
                    link0[force] *= held_force * u_rms / np.sum(link0[force])
                starts.append(np.concatenate([stage0, link0]))
    else:
        bla = best_linear_approximation(records)
        structure = None
        r = substeps or OpenLoop(bla).default_substeps(records[0].fs)
        c_scale = max(bla.c, 1e-3 * bla.m * 2 * np.pi * records[0].fs)
        scale = np.concatenate([[bla.m, c_scale, bla.k],
                                layout.scales(bla.k, c_scale, y_scale, v_scale)])
        starts = [np.concatenate([[bla.m, bla.c, stage * bla.k],
                                  layout.start(share * bla.k, y_scale, v_scale, bla.c, slip)])
                  for stage, share, slip in STARTS]
    n_plant = len((structure or MassSpringDamper).PARAMETERS)
    rate = np.concatenate([[False] * n_plant,
                           [par.unit == _VELOCITY for par, _ in layout._values()]])
    short = _short_records(records, periodic)
    n_eval = 0
    n_start = start_nfev or 15 * scale.size

    def held(p0: NDArray[np.float64], nfev: int):
        prob = _ElementProblem(short, periodic, r, layout, y_scale, scale, ~rate,
                               plant=structure)
        prob.fixed = prob.variables(p0)
        sol = prob.solve(prob.fixed[~rate], 1e-6, nfev)
        return sol.cost, prob.values(prob.whole(sol.x)), prob.n_eval

    best = None
    for p0 in starts:
        p0[rate] = RATE_GRID[0] * v_scale
        cost, p, used = held(p0, n_start)
        n_eval += used
        if best is None or cost < best[0]:
            best = (cost, p)
    profile = [best[0]]
    if rate.any():
        p_rest = best[1]
        for fraction in RATE_GRID[1:]:
            p0 = p_rest.copy()
            p0[rate] = fraction * v_scale
            cost, p, used = held(p0, n_start)
            n_eval += used
            profile.append(cost)
            if cost < best[0]:
                best = (cost, p)
    prob = _ElementProblem(records, periodic, r, layout, y_scale, scale, plant=structure)
    sol = prob.solve(prob.variables(best[1]), tol, max_nfev)
    v = prob.values(sol.x)
    res = prob.residuals(sol.x) * y_scale
    rss = float(res @ res)
    J = prob.jacobian(sol.x) * y_scale / prob.derivative(v)  # d residual / d parameter
    n_eval += prob.n_eval
    rtol = SINGULAR_RTOL if prob.exact else FD_SINGULAR_RTOL
    std_v, groups = _uncertainty(J, rss, res.size, rtol)
    names = [*prob.plant.PARAMETERS, *layout.names]
    estimates = {nm: float(x) for nm, x in zip(names, v, strict=True)}
    std: dict[str, float | None] = {}
    for nm, sd in zip(names, std_v, strict=True):
        std[nm] = float(sd) if math.isfinite(sd) else None
    not_ident = {f"link.{name}": _parallel_note(layout, name, structure)
                 for name in layout.fixed}
    not_ident.update(_undetermined_notes(names, groups, rtol))
    weak = _weak_notes(names, v, std_v, J, rtol, ~prob.log)
    n_short = sum(rec.y.size for rec in short)
    if rate.any() and _flat_profile(profile, n_short - scale.size):
        lo, hi = min(RATE_GRID) * v_scale, max(RATE_GRID) * v_scale
        for name in np.array(names)[rate]:
            weak[name] = (f"not determined by these records: held anywhere from {lo:.3g} to "
                          f"{hi:.3g} m/s, the other parameters fit the first record as well "
                          f"(likelihood ratio below {PROFILE_CHI2:g}, 95 %): the rate-dependent "
                          f"term is not seen, and the link's forces are its level at the "
                          f"records' velocities")
    for name, why in weak.items():
        if name not in not_ident:
            not_ident[name] = why
            std[name] = None
    return IOIdentification(
        plant=prob.plant.with_parameters(v[:n_plant]), hysteresis=layout.build(v[n_plant:]),
        estimates=estimates, std=std, not_identifiable=not_ident,
        fit_rms=float(np.sqrt(rss / res.size)), records=_per_record(records, res),
        seconds=time.perf_counter() - t_start, periodic=periodic,
        stopping=f"{sol.message} ({'exact' if prob.exact else 'finite-difference'} "
                 f"Jacobian; ftol = xtol = gtol = {tol:g}, "
                 f"at most {max_nfev} evaluations; {sol.nfev} used)",
        n_evaluations=n_eval, substeps=r)


#: 95 % point of the chi-square distribution with one degree of freedom
PROFILE_CHI2 = 3.84


def _flat_profile(costs: list[float], dof: int) -> bool:
    """True if no cost of a profile exceeds the least by the 95 % likelihood-ratio bound.

    ``(RSS_i - RSS_min) / sigma^2 < 3.84`` for every point, ``sigma^2 = RSS_min / dof``.
    """
    least = min(costs)
    return bool(least > 0 and (max(costs) - least) / least * max(dof, 1) < PROFILE_CHI2)


def _parallel_note(layout: _LinkLayout, name: str, plant=None) -> str:
    par = next(p for p in layout.cls.parameters if p.name == name)
    what, stage = ("a spring", "k") if par.parallel == "spring" else ("a damper", "c")
    if isinstance(plant, TwoMass):
        return (f"{what} to the ground in parallel with the link; not estimated with a "
                f"two-mass stage (which has none to the ground): fixed at 0")
    return (f"{what} in parallel with the stage's: only the sum {stage} + {name} enters the "
            f"output; fixed at 0, the stage's {stage} holds the sum")
