"""A measured frequency response fitted to a rigid body plus flexible modes (paper eqs. 1-2).

The paper's plant is ``P1 = Pr + Pf1`` and ``P2 = Pr - Pf2`` with the rigid
body ``Pr = 1 / (M s^2)`` (eq. 1).  A measured stage is fitted to the modal
form motion-control engineers use for it: the same rigid body and ``n``
flexible modes that the collocated ``P1`` and the non-collocated ``P2``
share::

    P1(s) = 1 / (M s^2) + sum_i r1_i / (s^2 + 2 z_i w_i s + w_i^2)
    P2(s) = 1 / (M s^2) - sum_i r2_i / (s^2 + 2 z_i w_i s + w_i^2)

with real residues (modal damping).  The two-mass stage of eq. (2) is the
case of one mode with ``r1 = m2 / (M m1)``, ``r2 = 1 / M``,
``w^2 = k M / (m1 m2)`` and ``2 z w = b M / (m1 m2)``.

Why a model: the mismatch of eq. (18) divides by ``Pf2 = Pr - P2``, which at
1 Hz is about 2e-6 of ``P2`` for Table I, far below the resolution of any
measurement.  The modes are seen where they are large (around and above
the resonances); the model carries ``Pf2`` down to low frequencies, where
``Pf2(0) = sum_i r2_i / w_i^2``.

Method
------
Weighted nonlinear least squares (:func:`scipy.optimize.least_squares`,
analytic Jacobian) of the relative complex error ``(P_model - P_data) /
|P_data|`` of ``P1`` and ``P2`` together, which is the maximum-likelihood
criterion for noise proportional to the response.  It starts from a
separable search: given the poles, the rigid body ``1/M`` and the residues
enter linearly, so each mode is added in turn by scanning its frequency
(50 per decade, from half the lowest to three times the highest measured
frequency) and damping (0.1 % to 20 %) with the other poles fixed and the
linear parameters solved exactly; then all parameters are refined together.
The scan finds a lightly damped mode that falls between measured lines,
where peak picking cannot.  (Vector fitting libraries on PyPI fit complex
pole-residue models of network parameters; they neither fix the double
pole at the origin nor keep modal residues real and shared between two
transfers, so the start is done here.)

The number of modes is given, or chosen as the first minimum of the
Bayesian information criterion ``BIC = N ln(RSS / N) + p ln N`` over
``n = 0, 1, 2, ...`` (``N`` real residuals, ``p`` parameters).
Uncertainties are one standard deviation from the Jacobian at the
solution, ``cov = s^2 (J^T J)^-1`` with ``s^2 = RSS / (N - p)``.

Delay
-----
A measurement chain delays both transfers by the same ``e^{-s tau}``
(sample-and-hold, computation, transport).  The fit is made a second time
with ``tau >= 0`` as one more parameter and the delay divided out of the
data, ``(P_model - P_data e^{s tau}) / |P_data|``, which has the modulus of
the error of the delayed model.  It starts from the delay at which the
separable scan's best rigid body plus one mode fits best, over a grid of
0.1 rad steps of phase at the highest line up to three turns (the 180 deg a
non-collocated ``P2`` loses above a mode is told apart from a delay only
with the mode); modes are then added as without a delay, the delay refined
with them.  Of the two, the fit with the lower BIC is kept (the delay costs
``ln N``), so data without a delay keep the fit without one.

Warnings
--------
:attr:`FrfFit.warnings` says, one line each, where the data are not what
the model describes: a negative ``Pf2(0)`` or a mode below the lowest line
(a stiffness to ground, such as a link that sticks), a ``Pf2(0)`` the data
do not determine to :data:`PF2_RELATIVE_STD`, a mode no passive
stage has, and a decade band whose RMS error is more than
:data:`RESIDUAL_NOISE_RATIO` times the line-to-line scatter of its errors
(the noise; an error the model leaves changes slowly from line to line).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares

from motionhyst.core.blas import few_blas_threads
from motionhyst.plants._frf_problem import DAMPING_BOUNDS, FREQ_BOUNDS, FrfProblem, candidates
from motionhyst.plants.frf_checks import MAX_FIT_LINES, check_response, thin_lines
from motionhyst.plants.measured import MeasuredPlant
from motionhyst.plants.modal import TWO_PI, ModalPlant, Mode
from motionhyst.plants.registry import PLAUSIBLE_MASS_KG

__all__ = ["FrfFit", "ModalPlant", "Mode", "damping_at_bound", "determined_modes",
           "fit_frf"]

#: Largest number of modes the automatic choice tries.
MAX_MODES = 6
def _start(prob: FrfProblem, x_prev, n_prev, tau: float | None = None):
    """Add one mode to the solution `x_prev` with `n_prev` modes by the separable scan.

    The data are taken with the delay of `x_prev` divided out, or with `tau` when given.
    """
    _, tau_prev, wn, z, _, _ = prob.unpack(x_prev, n_prev)
    tau = tau_prev if tau is None else tau
    W, Z = candidates(prob.f)
    best, _ = prob.linear_start(wn, z, (W, Z), tau=tau)
    wn2, z2 = np.append(wn, W[best]), np.append(z, Z[best])
    _, coef = prob.linear_start(wn2, z2, tau=tau)
    k = 0
    if prob.mass is None:
        a, k = coef[0], 1
        M = 1.0 / a if a > 0 else prob.unpack(x_prev, n_prev)[0]
    else:
        M = prob.mass
    r = coef[k:].reshape(-1, 2)
    return prob.pack(M, tau, wn2, z2, r[:, 0], r[:, 1])


#: Delays the start tries: steps of 0.1 rad of phase at the highest line, up to three turns.
_DELAY_STEP_RAD = 0.1
_DELAY_SCAN_TURNS = 3.0


def _delay_start(prob: FrfProblem) -> float:
    """The delay [s] at which a rigid body plus one mode (the scan of :func:`_start`) fits best.

    Every delay of a grid (phase steps of 0.1 rad at the highest measured line,
    up to three turns) divides the data; the best single mode of the scan is
    found for each.  A delay is told apart from the phase of the modes only
    with them: the non-collocated ``P2`` loses 180 deg above each mode.
    """
    w_max = TWO_PI * prob.f.max()
    taus = np.arange(0.0, _DELAY_SCAN_TURNS * TWO_PI, _DELAY_STEP_RAD) / w_max
    _, rss, _ = prob._scan(np.zeros(0), np.zeros(0), candidates(prob.f), taus)
    return float(taus[int(np.argmin(rss))])


def _bounds(prob: FrfProblem, n: int):
    w_lo = TWO_PI * prob.f.min() * FREQ_BOUNDS[0]
    w_hi = TWO_PI * prob.f.max() * FREQ_BOUNDS[1]
    lo = [-np.inf] if prob.mass is None else []
    hi = [np.inf] if prob.mass is None else []
    if prob.fit_delay:
        lo.append(0.0)
        hi.append(np.inf)
    for _ in range(n):
        lo += [np.log(w_lo), np.log(DAMPING_BOUNDS[0]), -np.inf, -np.inf]
        hi += [np.log(w_hi), np.log(DAMPING_BOUNDS[1]), np.inf, np.inf]
    return np.array(lo), np.array(hi)


def _solve(prob: FrfProblem, x0, n):
    lo, hi = _bounds(prob, n)
    x0 = np.clip(x0, np.nextafter(lo, hi), np.nextafter(hi, lo))
    if x0.size == 0:
        return x0, prob.residuals(x0, n)
    with few_blas_threads(4 * prob.f.size, x0.size):  # its SVDs: small, one thread
        sol = least_squares(prob.residuals, x0, jac=prob.jacobian, bounds=(lo, hi), args=(n,),
                            x_scale="jac", xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=500)
    return sol.x, sol.fun


@dataclass
class FrfFit:
    """Result of :func:`fit_frf`: the fitted :class:`ModalPlant`, its data and its quality.

    Attributes
    ----------
    plant : ModalPlant
        The fitted rigid body and modes.
    frequency_hz : ndarray
        Measured frequencies [Hz].
    P1_data, P2_data : ndarray of complex
        Measured responses [m/N] with the delay divided out, ``P e^{s tau}``
        (the measurement itself when ``delay_s`` is 0): what the plant is fitted to.
    M_std : float
        Standard deviation of ``M`` [kg] (0 when the mass was given).
    mode_std : list of dict
        Per mode, standard deviations of ``frequency_hz``, ``damping``, ``r1``, ``r2``.
    pf2_static_std : float
        Standard deviation of ``Pf2(0)`` [m/N].
    criterion : str
        How the number of modes was chosen.
    bic : dict
        ``{number of modes: BIC}`` of the fits tried.
    rms_relative_error : float
        RMS of ``|P_model - P_data| / |P_data|`` over both transfers.
    mass_given : bool
        True when ``M`` was fixed by the user.
    delay_s, delay_std_s : float
        Input-output delay ``tau`` [s] of ``e^{-s tau}``, common to ``P1`` and
        ``P2``, and its standard deviation; 0 when the fit without a delay has
        the lower BIC.  Not part of :attr:`plant`.
    delay_given : bool
        True when the delay was fixed by the user.
    bic_other : dict
        ``{number of modes: BIC}`` of the fits of the other kind: with a
        delay when the fit has none and the other way round (empty when the
        delay was given).
    warnings : list of str
        One line each where the data are not what the model describes: a
        stiffness to ground (a negative ``Pf2(0)``, a mode below the lowest
        line), a mode a passive stage does not have, errors far above the
        noise in a decade band.  Empty for a fit to trust.
    bic_modes : int or None
        The number of modes the BIC chose, before those the lines do not determine were
        dropped (:func:`fit_frf`); None where the modes were given.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst import ModalPlant, TwoMassStage, fit_frf
    >>> stage = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7))
    >>> f = np.geomspace(1.0, 3000.0, 60)
    >>> fit = fit_frf(f, *stage.response(2 * np.pi * f), source="stage.csv")
    >>> [b["lines"] for b in fit.bands()]                  # lines per decade band
    [17, 17, 17, 9]
    >>> print(str(fit).splitlines()[0])
    Fit of stage.csv: rigid body + 1 mode(s), 60 lines 1-3000 Hz (modes chosen by the BIC, ...)
    >>> sorted(fit.to_dict())[:3]
    ['M', 'M_std', 'bands']
    """

    plant: ModalPlant
    frequency_hz: NDArray[np.float64]
    P1_data: NDArray[np.complex128]
    P2_data: NDArray[np.complex128]
    M_std: float
    mode_std: list[dict]
    pf2_static_std: float
    criterion: str
    bic: dict = field(default_factory=dict)
    rms_relative_error: float = float("nan")
    mass_given: bool = False
    delay_s: float = 0.0
    delay_std_s: float = 0.0
    delay_given: bool = False
    bic_other: dict = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    bic_modes: int | None = None

    def _complex_errors(self) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
        """``(P_model - P_data) / |P_data|`` of ``P1`` and ``P2`` at each measured frequency."""
        m1, m2 = self.plant.response(TWO_PI * self.frequency_hz)
        return ((m1 - self.P1_data) / np.abs(self.P1_data),
                (m2 - self.P2_data) / np.abs(self.P2_data))

    def relative_errors(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``|P_model - P_data| / |P_data|`` of ``P1`` and ``P2`` at each measured frequency.

        The same as ``|P_model e^{-s tau} - P_measured| / |P_measured|``.
        """
        c1, c2 = self._complex_errors()
        return np.abs(c1), np.abs(c2)

    def bands(self) -> list[dict]:
        """Fit quality per decade band of the measured range.

        Returns
        -------
        list of dict
            ``f_lo_hz``, ``f_hi_hz``, ``lines`` (measured frequencies in the
            band), and the RMS and largest relative error of ``P1`` and ``P2``.
        """
        e1, e2 = self.relative_errors()
        f = self.frequency_hz
        edges = 10.0 ** np.arange(np.floor(np.log10(f.min())), np.ceil(np.log10(f.max())) + 1)
        out = []
        for lo, hi in itertools.pairwise(edges):
            sel = (f >= lo) & (f < hi) if hi < edges[-1] else (f >= lo) & (f <= hi)
            if not sel.any():
                continue
            out.append({"f_lo_hz": float(max(lo, f[sel].min())), "f_hi_hz": float(f[sel].max()),
                        "lines": int(sel.sum()),
                        "p1_rms_rel": float(np.sqrt(np.mean(e1[sel] ** 2))),
                        "p1_max_rel": float(e1[sel].max()),
                        "p2_rms_rel": float(np.sqrt(np.mean(e2[sel] ** 2))),
                        "p2_max_rel": float(e2[sel].max())})
        return out

    def to_dict(self) -> dict:
        """JSON-ready dictionary (the ``plant_fit`` block of ``analyze --json``)."""
        p = self.plant
        return {
            "model": "rigid body + modes (modal form, shared poles)",
            "M": p.M, "M_std": self.M_std, "mass_given": self.mass_given,
            "modes": [{"frequency_hz": m.frequency_hz, "frequency_hz_std": s["frequency_hz"],
                       "damping": m.damping,
                       "damping_std": None if damping_at_bound(m.damping) else s["damping"],
                       "damping_at_bound": damping_at_bound(m.damping),
                       "r1": m.r1, "r1_std": s["r1"], "r2": m.r2, "r2_std": s["r2"]}
                      for m, s in zip(p.modes, self.mode_std, strict=True)],
            "bic_modes": self.bic_modes,
            "pf2_static": p.pf2_static, "pf2_static_std": self.pf2_static_std,
            "criterion": self.criterion,
            "bic": {str(k): v for k, v in self.bic.items()},
            "lines": int(self.frequency_hz.size),
            "frequency_range_hz": [float(self.frequency_hz.min()),
                                   float(self.frequency_hz.max())],
            "rms_relative_error": self.rms_relative_error,
            "bands": self.bands(),
            "delay_s": self.delay_s, "delay_std_s": self.delay_std_s,
            "delay_given": self.delay_given,
            "bic_other": {str(k): v for k, v in self.bic_other.items()},
            "warnings": list(self.warnings),
        }

    def __str__(self) -> str:
        p = self.plant
        f = self.frequency_hz
        lines = [f"Fit of {p.source or 'measured FRF'}: rigid body + {len(p.modes)} mode(s), "
                 f"{f.size} lines {_num(f.min())}-{_num(f.max())} Hz ({self.criterion})",
                 f"  M = {_pm(p.M, self.M_std)} kg" + (" (given)" if self.mass_given else "")]
        for i, (m, s) in enumerate(zip(p.modes, self.mode_std, strict=True), start=1):
            lines.append(f"  mode {i}: f = {_pm(m.frequency_hz, s['frequency_hz'])} Hz, "
                         f"damping = {_damping(m.damping, s['damping'])}, "
                         f"r1 = {_pm(m.r1, s['r1'])} 1/kg, r2 = {_pm(m.r2, s['r2'])} 1/kg")
        lines.append(f"  Pf2(0) = {_pm(p.pf2_static, self.pf2_static_std)} m/N "
                     f"(flexible compliance at P2; sets eqs. 18-21 at low frequency)")
        if self.delay_given:
            lines.append(f"  delay = {_num(self.delay_s * 1e6)} us (given; divided out of the "
                         f"data)")
        elif self.delay_s > 0:
            lines.append(f"  delay = {_pm(self.delay_s * 1e6, self.delay_std_s * 1e6)} us "
                         f"(e^(-s tau) of the measurement chain on P1 and P2, divided out of "
                         f"the data: the plant is without it)")
        else:
            lines.append("  delay = 0 (a delay e^(-s tau) on P1 and P2 does not lower the BIC)")
        lines.append("  relative error |P_fit - P_data|/|P_data|: RMS "
                     f"{_num(self.rms_relative_error)} over both transfers; per band:")
        for b in self.bands():
            lines.append(f"    {_num(b['f_lo_hz']):>6}-{_num(b['f_hi_hz']):<6} Hz "
                         f"{b['lines']:>3} lines  P1 RMS {_num(b['p1_rms_rel'])} "
                         f"(max {_num(b['p1_max_rel'])}), P2 RMS {_num(b['p2_rms_rel'])} "
                         f"(max {_num(b['p2_max_rel'])})")
        lines += [f"  warning: {w}" for w in self.warnings]
        return "\n".join(lines)

    def plot(self, f_range: tuple[float, float] | None = None, ax=None):
        """Bode figure of the measured ``P1``, ``P2`` (markers) and the fit (lines).

        Returns a matplotlib Figure (see :func:`motionhyst.plants.figures.plot_frf_fit`).

        Parameters
        ----------
        f_range : (float, float), optional
            Frequency range [Hz]; default: the data's, widened by 1.5 each side.
        ax : sequence of 2 matplotlib.axes.Axes, optional
            Axes to draw into (magnitude, phase); default: a new figure.
        """
        from motionhyst.plants.figures import plot_frf_fit

        return plot_frf_fit(self, f_range, ax=ax)


def _num(x: float) -> str:
    return "nan" if not np.isfinite(x) else f"{x:.4g}"


def damping_at_bound(damping: float) -> bool:
    """True for a mode's damping ratio at a bound of the fit (:data:`DAMPING_BOUNDS`, within
    0.1 %): its standard deviation is then not the data's (the covariance drops the
    direction the bound holds), nor is the value determined.

    Parameters
    ----------
    damping : float
        A fitted mode's damping ratio.

    Returns
    -------
    bool

    Examples
    --------
    >>> damping_at_bound(1e-5), damping_at_bound(2.6e-3), damping_at_bound(1.0)
    (True, False, True)
    """
    return bool(damping <= DAMPING_BOUNDS[0] * 1.001 or damping >= DAMPING_BOUNDS[1] * 0.999)


def _damping(v: float, s: float) -> str:
    """A damping ratio and its standard deviation, or "(at its bound)" where the fit holds it
    at one."""
    return f"{_num(v)} (at its bound)" if damping_at_bound(v) else _pm(v, s)


def _pm(v: float, s: float) -> str:
    if s == 0:
        return _num(v)
    if not np.isfinite(s):
        return f"{_num(v)} +- (not determined)"
    return f"{_num(v)} +- {s:.2g}"


#: Relative error below which a fit counts as exact (the BIC does not reward fitting round-off).
EXACT_RELATIVE_ERROR = 1e-9


def _bic(rss: float, n_res: int, n_par: int) -> float:
    mse = max(rss / n_res, EXACT_RELATIVE_ERROR**2)
    return float(n_res * np.log(mse) + n_par * np.log(n_res))


def fit_frf(frequency_hz: ArrayLike, P1: ArrayLike, P2: ArrayLike, modes: int | None = None,
            mass: float | None = None, max_modes: int = MAX_MODES, source: str = "",
            delay: float | None = None) -> FrfFit:
    """Fit measured ``P1``, ``P2`` to a rigid body plus flexible modes (eqs. 1-2, modal form).

    The data may lag the mechanics by a pure delay ``e^{-s tau}`` common to
    ``P1`` and ``P2`` (sample-and-hold, computation, the measurement chain):
    it is estimated with the modes and kept when it lowers the BIC (module
    docstring), and divided out of the data; the fitted plant is the
    mechanics without it.

    Modes the BIC chooses but the lines do not determine (:func:`determined_modes`:
    needles between or beside the lowest lines fitting their noise) are dropped: the
    fit is made again with the modes the lines determine (at least one when the BIC
    chose several, which may split a determined mode in two), until every mode is
    determined; :attr:`FrfFit.criterion` says so and :attr:`FrfFit.bic_modes` keeps
    the BIC's number.  Where the lines determine none of them, the BIC's fit is
    returned with a first warning saying so (:data:`NONE_DETERMINED`).  Given `modes`
    are fitted as they are.

    Parameters
    ----------
    frequency_hz : array_like
        Measured frequencies [Hz], positive and increasing.
    P1, P2 : array_like of complex
        Measured collocated and non-collocated responses [m/N].
    modes : int, optional
        Number of flexible modes; default: chosen by the BIC (module docstring).
    mass : float, optional
        Rigid-body mass [kg]; fixed when given, else fitted.
    max_modes : int
        Largest number of modes the automatic choice tries.
    source : str
        Where the data came from (for the report).
    delay : float, optional
        Input-output delay ``tau`` [s], >= 0, divided out of the data; default:
        estimated (0 when the data show none).

    Returns
    -------
    FrfFit
        With :attr:`FrfFit.warnings` when the data are not what the model
        describes (a stiffness to ground, errors far above the noise).

    Raises
    ------
    ValueError
        Too few lines for the number of parameters, non-finite or zero data,
        a negative delay; data refused before the fit (:func:`~motionhyst.plants.frf_checks.
        check_response`: not a rigid body at low frequency, a delay, units or phase sense).

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.plants.frf_fit import ModalPlant, fit_frf
    >>> from motionhyst.plants.two_mass import TwoMassStage
    >>> exact = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7))
    >>> f = np.geomspace(1.0, 3000.0, 60)
    >>> p1, p2 = exact.response(2 * np.pi * f)
    >>> fit = fit_frf(f, p1, p2)
    >>> len(fit.plant.modes), round(fit.plant.M, 6), round(fit.plant.modes[0].frequency_hz, 3)
    (1, 22.5, 694.262)
    >>> fit.delay_s, fit.warnings
    (0.0, [])

    The same stage measured through a chain that delays it by 50 us:

    >>> lag = np.exp(-2j * np.pi * f * 50e-6)
    >>> fit = fit_frf(f, p1 * lag, p2 * lag)
    >>> len(fit.plant.modes), round(fit.delay_s * 1e6, 3), round(fit.plant.M, 6)
    (1, 50.0, 22.5)

    With 0.5 % noise the BIC puts needles between the lowest lines, which the lines do not
    determine; they are dropped:

    >>> rng = np.random.default_rng(1)
    >>> noise = 1 + 0.005 * rng.standard_normal((2, f.size))
    >>> fit = fit_frf(f, p1 * noise[0], p2 * noise[1])
    >>> [round(m.frequency_hz) for m in fit.plant.modes], fit.bic_modes
    ([694], 5)
    >>> fit.criterion.split(";")[0]
    "the BIC's 5 modes less 4 the lines do not determine"
    """
    bic = _fit_frf(frequency_hz, P1, P2, modes, mass, max_modes, source, delay)
    if modes is not None:
        return bic
    fit, chosen = bic, len(bic.plant.modes)
    while (n := sum(determined_modes(fit))) < len(fit.plant.modes):
        # one mode is tried before none: the BIC may split a mode the lines determine into
        # two, each undetermined alone
        n = max(n, 1) if len(fit.plant.modes) > 1 else 0
        if n == 0:  # none determined: the BIC's fit, saying so (a scenario refuses it)
            fit = bic
            fit.warnings.insert(0, f"{NONE_DETERMINED} the {fit.frequency_hz.size} lines "
                                f"({_num(fit.frequency_hz.min())}-{_num(fit.frequency_hz.max())}"
                                f" Hz) determine none of the {chosen} mode(s) the BIC chose: "
                                f"the modes, Pf2(0) and |E| are not the data's; measure up to "
                                f"and beyond the first resonance")
            break
        fit = _fit_frf(frequency_hz, P1, P2, n, mass, max_modes, source, delay)
        fit.criterion = fit.criterion.replace(
            "modes given", f"the BIC's {chosen} modes less {chosen - n} the lines do not "
            f"determine", 1)
    fit.bic_modes = chosen
    return fit


def _fit_frf(frequency_hz: ArrayLike, P1: ArrayLike, P2: ArrayLike, modes: int | None,
             mass: float | None, max_modes: int, source: str, delay: float | None) -> FrfFit:
    """:func:`fit_frf` with the modes the BIC chooses (`modes` None) or those given, as they
    are."""
    f = np.asarray(frequency_hz, dtype=float).ravel()
    p1 = np.asarray(P1, dtype=complex).ravel()
    p2 = np.asarray(P2, dtype=complex).ravel()
    if not (f.size == p1.size == p2.size):
        raise ValueError("frequency_hz, P1 and P2 must have the same length")
    if not (np.all(np.isfinite(f)) and np.all(np.isfinite(p1)) and np.all(np.isfinite(p2))):
        raise ValueError("non-finite value in the frequency response")
    if np.any(f <= 0) or np.any(np.diff(f) <= 0):
        raise ValueError("frequency_hz must be positive and increasing")
    if np.any(p1 == 0) or np.any(p2 == 0):
        raise ValueError("a measured response is exactly zero")
    if mass is not None and not (np.isfinite(mass) and mass > 0):
        raise ValueError(f"mass must be finite and > 0, got {mass!r}")
    if delay is not None:
        if not (np.isfinite(delay) and delay >= 0):
            raise ValueError(f"delay must be finite and >= 0, got {delay!r}")
        delay = float(delay)
    n_measured = f.size
    if f.size > MAX_FIT_LINES:  # a dense response: the fit's size bounded, not the data's
        keep = thin_lines(f, p1, p2)
        f, p1, p2 = f[keep], p1[keep], p2[keep]
    check_response(f, p1, p2, mass, delay)
    if delay:  # divided out: the fit is that of the mechanics
        rot = np.exp(1j * TWO_PI * f * delay)
        p1, p2 = p1 * rot, p2 * rot
    n_res = 4 * f.size
    n_fixed = 0 if mass is not None else 1
    if modes is not None:
        if int(modes) != modes or modes < 0:
            raise ValueError(f"modes must be a whole number >= 0, got {modes!r}")
        modes = int(modes)
        if 2 * (n_fixed + 4 * modes) > n_res:
            raise ValueError(f"{f.size} measured lines cannot determine {modes} modes "
                             f"({n_fixed + 4 * modes} parameters from {n_res} real values; "
                             f"at least twice as many values as parameters are needed)")
    prob = FrfProblem(f, p1, p2, mass)
    if mass is None:
        # start: the rigid body of the lowest decade, -1 / (omega^2 Re P), both transfers
        # (positive: check_response)
        low = f <= f[0] * 10.0
        w2 = (TWO_PI * f[low]) ** 2
        a0 = float(np.median(np.concatenate([-w2 * p1[low].real, -w2 * p2[low].real])))
        x = np.array([np.log(1.0 / a0)])
    else:
        x = np.zeros(0)
    fits, bic = _chain(prob, x, n_res, modes, max_modes)
    n_best = _choose(bic, modes)
    chosen, other = (prob, fits, bic, n_best), {}
    if delay is None:
        probd = FrfProblem(f, p1, p2, mass, fit_delay=True)
        tau0 = _delay_start(probd)
        fits_d, bic_d = _chain(probd, np.append(x, tau0), n_res, modes, max_modes, tau0)
        other = bic_d
        if modes is None or modes in fits_d:
            nd = _choose(bic_d, modes)
            if probd.unpack(fits_d[nd][0], nd)[1] > 0 and bic_d[nd] < bic[n_best]:
                chosen, other = (probd, fits_d, bic_d, nd), bic
    prob, fits, bic, n_best = chosen
    if modes is None:
        criterion = (f"modes chosen by the BIC, first minimum over n = 0..{max(bic)}")
    else:
        criterion = "modes given"
    if f.size < n_measured:
        criterion += (f"; fitted to {f.size} of the {n_measured} measured lines, log-spaced "
                      f"with the peaks kept")
    x, rss = fits[n_best]
    fit = _result(prob, x, n_best, rss, criterion, bic, source)
    fit.bic_other = other
    if delay is not None:
        fit.delay_s, fit.delay_given = delay, True
    fit.warnings = _diagnose(fit)
    return fit


def _chain(prob: FrfProblem, x0, n_res: int, modes: int | None, max_modes: int,
           tau_first: float | None = None):
    """Fits with 0, 1, 2, ... modes, each started from the one before (module docstring).

    Up to `modes`, or to the first minimum of the BIC.  `tau_first`: a delay
    the scan for the first mode also divides out, besides that of the fit
    without modes (which a mode's phase can pull away); the better fit is kept.
    Returns ``{n: (x, rss)}`` and ``{n: BIC}``.
    """
    x, r = _solve(prob, x0, 0)
    fits = {0: (x, float(r @ r))}
    bic = {0: _bic(fits[0][1], n_res, prob.n_head)}
    target = modes if modes is not None else max_modes
    for n in range(1, target + 1):
        if 2 * (prob.n_head + 4 * n) > n_res:
            break
        taus = [None]
        if n == 1 and tau_first is not None and tau_first != prob.unpack(fits[0][0], 0)[1]:
            taus.append(tau_first)
        tries = []
        for tau in taus:
            x, r = _solve(prob, _start(prob, fits[n - 1][0], n - 1, tau), n)
            tries.append((float(r @ r), len(tries), x))
        rss, _, x = min(tries)
        fits[n] = (x, rss)
        bic[n] = _bic(fits[n][1], n_res, prob.n_head + 4 * n)
        if modes is None and bic[n] >= bic[n - 1]:
            break
    return fits, bic


def _choose(bic: dict, modes: int | None) -> int:
    """The number of modes: given, or that of the lowest BIC."""
    return modes if modes is not None else min(bic, key=lambda k: (bic[k], k))


def _result(prob: FrfProblem, x, n, rss, criterion, bic, source) -> FrfFit:
    M, tau, wn, z, r1, r2 = prob.unpack(x, n)
    n_res = 4 * prob.f.size
    n_par = x.size
    if n_par:
        J = prob.jacobian(x, n)
        s2 = rss / max(n_res - n_par, 1)
        cov = s2 * np.linalg.pinv(J.T @ J)
        std_x = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    else:
        cov = np.zeros((0, 0))
        std_x = np.zeros(0)
    k = prob.n_head
    M_std = float(M * std_x[0]) if prob.mass is None else 0.0
    tau_std = float(std_x[k - 1]) if prob.fit_delay else 0.0
    sx = std_x[k:].reshape(n, 4) if n else np.zeros((0, 4))
    mode_std = [{"frequency_hz": float(wn[i] / TWO_PI * sx[i, 0]),
                 "damping": float(z[i] * sx[i, 1]), "r1": float(sx[i, 2]),
                 "r2": float(sx[i, 3])} for i in range(n)]
    # Pf2(0) = sum r2_i / w_i^2: gradient in (ln w_i, r2_i)
    grad = np.zeros(n_par)
    for i in range(n):
        grad[k + 4 * i] = -2.0 * r2[i] / wn[i] ** 2
        grad[k + 4 * i + 3] = 1.0 / wn[i] ** 2
    pf2_std = float(np.sqrt(max(grad @ cov @ grad, 0.0))) if n_par else 0.0
    modes = [Mode(float(wn[i] / TWO_PI), float(z[i]), float(r1[i]), float(r2[i]))
             for i in range(n)]
    order = np.argsort([m.frequency_hz for m in modes])
    plant = ModalPlant(M, [modes[i] for i in order], source=source)
    d1, d2 = prob.data(tau)
    fit = FrfFit(plant=plant, frequency_hz=prob.f, P1_data=d1, P2_data=d2,
                 M_std=M_std, mode_std=[mode_std[i] for i in order], pf2_static_std=pf2_std,
                 criterion=criterion, bic=bic, mass_given=prob.mass is not None,
                 delay_s=tau, delay_std_s=tau_std)
    e1, e2 = fit.relative_errors()
    fit.rms_relative_error = float(np.sqrt(np.mean(np.concatenate([e1, e2]) ** 2)))
    return fit


#: How the warning of a fit whose lines determine none of its modes begins (:func:`fit_frf`;
#: a scenario refuses such a fit).
NONE_DETERMINED = "measured plant: no mode determined:"

#: A fitted mode is seen by the lines when it changes ``P1`` or ``P2`` at one of them by more
#: than this many times the data's noise (:func:`determined_modes`); a peak narrower than the
#: lines resolve, next to them, needs :data:`NEEDLE_SEEN_RATIO` times.
SEEN_RATIO = 5.0
NEEDLE_SEEN_RATIO = 50.0


def determined_modes(fit: FrfFit) -> list[bool]:
    """Whether the measured lines determine each fitted mode (in the order of ``fit.plant.modes``).

    A mode is determined when its collocated residue ``r1`` (how strongly the
    force moves it) stands more than one standard deviation from zero, and
    when it changes the response at one of the lines, ``max |r g(w)| / |P|``
    over ``P1`` and ``P2``, by more than :data:`SEEN_RATIO` times the data's
    noise (the fit's RMS complex relative error, counted over the values the
    parameters leave free).  A "needle", a peak narrower than the lines
    resolve (its half-power band ``2 z f`` narrower than the distance to the
    nearest line) next to them (that distance below the spacing of the lines
    there), is what the scan of candidate poles places between or beside
    lines to fit their noise: it must change a line by
    :data:`NEEDLE_SEEN_RATIO` times the noise.  The lowest 3-12 lines of a
    stage resonating at 695 Hz, with 0.5 % noise, gave needles at 0.9-4 Hz
    changing a line by 0.3-1.6 %, 2-16 times the noise; the stage's mode,
    between two lines 90 Hz apart, changes them by 19 times the response,
    thousands of times the noise.  A mode beyond the lines by more than their
    spacing is seen through its compliance ``r / w^2`` alone: its damping
    does not matter there.

    Parameters
    ----------
    fit : FrfFit
        A fit of :func:`fit_frf`.

    Returns
    -------
    list of bool
        One per mode of ``fit.plant.modes``.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.plants.frf_fit import ModalPlant, determined_modes, fit_frf
    >>> from motionhyst.plants.two_mass import TwoMassStage
    >>> stage = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7))
    >>> f = np.geomspace(1.0, 3000.0, 60)
    >>> p1, p2 = stage.response(2 * np.pi * f)
    >>> noise = 1 + 0.005 * np.random.default_rng(0).standard_normal((2, f.size))
    >>> determined_modes(fit_frf(f, p1 * noise[0], p2 * noise[1]))
    [True]
    >>> fit = fit_frf(f[:3], p1[:3] * noise[0, :3], p2[:3] * noise[1, :3], modes=1)  # 1-1.3 Hz
    >>> [round(m.frequency_hz, 2) for m in fit.plant.modes], determined_modes(fit)
    ([1.23], [False])
    >>> print(fit_frf(f[:3], p1[:3] * noise[0, :3], p2[:3] * noise[1, :3]).warnings[0])
    measured plant: no mode determined: the 3 lines (1-1.312 Hz) determine none of the 1 \
mode(s) the BIC chose: the modes, Pf2(0) and |E| are not the data's; measure up to and beyond \
the first resonance
    """
    p, f = fit.plant, fit.frequency_hz
    if not p.modes:
        return []
    c1, c2 = fit._complex_errors()
    n_par = int(not fit.mass_given) + int(fit.delay_s > 0 and not fit.delay_given) \
        + 4 * len(p.modes)
    rss = float(np.sum(np.abs(c1) ** 2 + np.abs(c2) ** 2))  # of the 4 f.size real residuals
    noise = np.sqrt(2.0 * rss / max(4 * f.size - n_par, 1))  # complex, per value
    s = 1j * TWO_PI * f
    out = []
    for m, std in zip(p.modes, fit.mode_std, strict=True):
        w = TWO_PI * m.frequency_hz
        g = 1.0 / (s**2 + 2.0 * m.damping * w * s + w**2)
        share = max(float(np.max(np.abs(m.r1 * g) / np.abs(fit.P1_data))),
                    float(np.max(np.abs(m.r2 * g) / np.abs(fit.P2_data))))
        i = int(np.clip(np.searchsorted(f, m.frequency_hz), 1, max(f.size - 1, 1)))
        spacing = float(f[i] - f[i - 1]) if f.size > 1 else np.inf
        near = float(np.min(np.abs(f - m.frequency_hz)))
        needle = 2.0 * m.damping * m.frequency_hz < near < spacing
        ratio = NEEDLE_SEEN_RATIO if needle else SEEN_RATIO
        out.append(bool(std["r1"] < abs(m.r1) and share > ratio * noise))
    return out


#: A band's RMS error this many times the line-to-line scatter of its errors is far above
#: the noise (for noise alone the ratio is 1, within about 0.2 for a band of 9 lines).
RESIDUAL_NOISE_RATIO = 2.0
#: How the warning of errors far above the noise begins (a scenario refuses such a fit).
ABOVE_NOISE = "measured plant: fit errors far above the data's noise"
#: Relative standard deviation of Pf2(0) above which it is not determined by the data.
PF2_RELATIVE_STD = 0.1
#: Fewest lines of a band checked for errors above its noise.
_RESIDUAL_MIN_LINES = 5
#: Relative errors below this are far below any measurement's noise: never warned about.
_RESIDUAL_FLOOR = 1e-6


def _diagnose(fit: FrfFit) -> list[str]:
    """One-line warnings where the data are not what the model describes (:attr:`FrfFit.warnings`).

    - a stiffness to ground: a negative ``Pf2(0)`` or a mode below the lowest
      line (the lowest lines are then not a floating rigid body);
    - ``Pf2(0)`` not determined: its standard deviation above
      :data:`PF2_RELATIVE_STD` of it (the modes lie beyond the measured lines);
    - modes a passive stage does not have: a negative collocated residue
      ``r1`` (by more than 3 standard deviations) or a damping ratio at its bound, but for
      a mode with a positive ``r1`` at the lower bound: a stage's mode lighter than the
      lines resolve, its damping not an estimate;
    - a rigid-body mass outside :data:`PLAUSIBLE_MASS_KG` (a unit slip: kHz for Hz);
    - errors far above the noise: in a decade band, the RMS of the complex
      relative error more than :data:`RESIDUAL_NOISE_RATIO` times its
      line-to-line scatter ``sqrt(mean |e_i+1 - e_i|^2 / 2)``, which noise
      alone makes equal to the RMS while an error the model leaves varies
      slowly from line to line.
    """
    p, f = fit.plant, fit.frequency_hz
    out = []
    if not fit.mass_given and not PLAUSIBLE_MASS_KG[0] <= p.M <= PLAUSIBLE_MASS_KG[1]:
        out.append(f"measured plant: M = {p.M:.3g} kg, outside the {PLAUSIBLE_MASS_KG[0]:g}-"
                   f"{PLAUSIBLE_MASS_KG[1]:g} kg of motion stages: check the units (frequency_hz "
                   f"in kHz makes M 1e6 times too large, a response in um/N or mm/N 1e6 or 1e3 "
                   f"times too small)")
    low = [m for m in p.modes if m.frequency_hz < f.min()]
    if p.pf2_static < 0 or low:
        what = ([f"Pf2(0) = {p.pf2_static:.3g} m/N < 0"] if p.pf2_static < 0 else []) + [
            f"a mode at {_num(m.frequency_hz)} Hz below the lowest line {_num(f.min())} Hz"
            for m in low]
        out.append(f"measured plant: the lowest lines are not a floating rigid body "
                   f"({', '.join(what)}): a stiffness to ground, such as a sticking link, that "
                   f"the stage of eqs. 1-2 lacks; |E| at low frequencies is wrong; measure with "
                   f"the link sliding or detached")
    elif p.modes and not fit.pf2_static_std <= PF2_RELATIVE_STD * p.pf2_static:
        out.append(f"measured plant: Pf2(0) = {_pm(p.pf2_static, fit.pf2_static_std)} m/N is not "
                   f"determined to {PF2_RELATIVE_STD:.0%} by the data, nor is |E| at low "
                   f"frequencies (eq. 20 divides by it); measure up to and beyond the first mode")
    odd, light = [], []
    for i, (m, s) in enumerate(zip(p.modes, fit.mode_std, strict=True), start=1):
        why = []
        if m.r1 < -3 * s["r1"]:
            why.append(f"r1 = {_num(m.r1)} 1/kg < 0")
        if (m.damping <= DAMPING_BOUNDS[0] * 1.001 and m.r1 > 0 and not why
                and m not in low):  # a stage's mode, its width unresolved
            light.append(f"mode {i} at {_num(m.frequency_hz)} Hz")
        elif damping_at_bound(m.damping):
            why.append(f"damping at its bound {_num(m.damping)}")
        if why and m not in low:  # those are in the warning above
            odd.append(f"mode {i} at {_num(m.frequency_hz)} Hz ({', '.join(why)})")
    if light:
        out.append(f"measured plant: {'; '.join(light)}: lighter than the lines resolve (its "
                   f"peak falls between them): the damping ratio {_num(DAMPING_BOUNDS[0])} is "
                   f"the fit's lower bound, not an estimate; lines closer to it resolve it")
    if odd:
        out.append(f"measured plant: {'; '.join(odd)}: not a mode of a passive stage (positive "
                   f"collocated residue, resonant); the fit uses it for something the model "
                   f"lacks")
    c1, c2 = fit._complex_errors()
    high = []
    for b in fit.bands():
        sel = np.nonzero((f >= b["f_lo_hz"]) & (f <= b["f_hi_hz"]))[0]
        if sel.size < _RESIDUAL_MIN_LINES:
            continue
        e = np.concatenate([c1[sel], c2[sel]])
        d = np.concatenate([np.diff(c1[sel]), np.diff(c2[sel])])
        rms, scatter = np.sqrt(np.mean(np.abs(e) ** 2)), np.sqrt(np.mean(np.abs(d) ** 2) / 2)
        if rms > _RESIDUAL_FLOOR and rms > RESIDUAL_NOISE_RATIO * scatter:
            high.append((b["f_lo_hz"], b["f_hi_hz"], rms, rms / max(scatter, 1e-300)))
    if high:
        where = ", ".join(f"{_num(lo)}-{_num(hi)} Hz (RMS {_num(r)}, {q:.2g} x)"
                          for lo, hi, r, q in high)
        out.append(f"{ABOVE_NOISE} (their line-to-line scatter) at {where}: the data hold "
                   f"something a rigid body plus modes and a pure delay does not describe (a "
                   f"stiffness to ground, amplifier or sensor dynamics, a missing mode)")
    return out


def fit_measured_plant(plant: MeasuredPlant, modes: int | None = None,
                       mass: float | None = None, delay: float | None = None) -> FrfFit:
    """Fit a :class:`~motionhyst.plants.measured.MeasuredPlant` (see :func:`fit_frf`).

    `mass` fixes ``M``; by default it is fitted (the plant's own estimate of
    ``M`` from its lowest decade is not used).  `delay` fixes the delay [s];
    by default it is estimated.
    """
    f = plant.P2.omega / TWO_PI
    p1 = np.asarray(plant.P1.frdata, dtype=complex).ravel()
    p2 = np.asarray(plant.P2.frdata, dtype=complex).ravel()
    return fit_frf(f, p1, p2, modes=modes, mass=mass, source=plant.source, delay=delay)
