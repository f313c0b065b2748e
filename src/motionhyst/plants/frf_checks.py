"""What a measured response is refused for before its fit (:mod:`motionhyst.plants.frf_fit`).

Checks on the measured ``P1``, ``P2`` of a stage (paper eq. 1) that need no fit,
each refusing with one line that names the cause:

- the rigid body at the lowest lines: ``P1`` and ``P2`` there are both ``1/(M s^2)``
  (``Re P < 0``), a stage's flexible part being small below its first mode;
- a given delay ``tau`` that, divided out, turns lowest lines that are a rigid body
  into lines that are not (:func:`check_delay`);
- ``P1`` and ``P2`` that differ by orders of magnitude at the lowest lines: one
  transfer in other units (:func:`check_transfers_agree`);
- phases of the opposite sign convention, ``P(-j w)`` for ``P(j w)``: a collocated
  ``P1`` is passive, ``Im P1(j w) <= 0`` once a delay ``tau >= 0`` is divided out,
  and its conjugate is not (:func:`check_phase_sense`).

They cost milliseconds where the fit costs a second or more, and python-control is
not loaded for them.  A dense response is judged, and fitted, on the lines
:func:`thin_lines` keeps.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from motionhyst.plants.modal import TWO_PI

__all__ = ["MAX_FIT_LINES", "FrfInputError", "check_delay", "check_phase_sense",
           "check_response", "check_transfers_agree", "rigid_body_share", "thin_lines"]

#: ``P1`` and ``P2`` at the lowest lines differing by more than this factor are not one
#: stage's: a unit slip on one of them (mm/N or um/N for m/N: 1e3, 1e6).
TRANSFER_RATIO_MAX = 100.0
#: Lowest lines counted as "the lowest": up to this factor above the lowest frequency.
_LOWEST_SPAN = 2.0
#: A line is a rigid body's when its phase is within 60 deg of -180 deg: the median of
#: ``-Re P / |P|`` (the cosine of that angle) over the lowest decade at least this.
RIGID_SHARE_MIN = 0.5
#: The phase sense is judged when the conjugate's passivity violation (RMS of the positive
#: part of ``Im P1 / |P1|``, the best delay divided out) is this many times the data's,
#: over at least :data:`_PHASE_MIN_LINES` lines.
PHASE_SENSE_RATIO = 4.0
_PHASE_MIN_LINES = 10
#: ... and the conjugate is passive within the data's noise: its violation at most the RMS of
#: ``Im P1 / |P1|`` over the lowest decade (a rigid body's is 0), or this where that is less.
_PHASE_FLOOR = 1e-3
#: Delays tried: steps of this phase at the highest line, up to three turns.
_DELAY_STEP_RAD = 0.01
_DELAY_TURNS = 3.0


#: Most measured lines a fit uses: a denser response is thinned (:func:`thin_lines`).
MAX_FIT_LINES = 1000


def thin_lines(f: NDArray[np.float64], p1: NDArray[np.complex128], p2: NDArray[np.complex128],
               n_max: int = MAX_FIT_LINES) -> NDArray[np.intp]:
    """Indices of at most about `n_max` lines of a dense response: log-spaced, peaks kept.

    A measured response of more lines than a fit needs (a swept sine logged at
    every sample, 1e6 lines) is thinned to lines evenly spaced in log frequency,
    plus the three lines around each of the largest peaks of ``|P| w^2`` (the
    response relative to a rigid body), where a lightly damped mode is narrow.

    Parameters
    ----------
    f : ndarray
        Frequencies [Hz], increasing.
    p1, p2 : ndarray of complex
        Responses at `f`.
    n_max : int
        Lines to keep, about (at least 20).

    Returns
    -------
    ndarray of int
        Increasing indices into `f`; all of them when ``f.size <= n_max``.

    Examples
    --------
    >>> import numpy as np
    >>> f = np.linspace(1.0, 1000.0, 100_000)
    >>> p = -1.0 / (22.5 * (2 * np.pi * f) ** 2) * (1 + 0.5 * (np.abs(f - 700.0) < 0.02))
    >>> keep = thin_lines(f, p, p, 200)
    >>> len(keep) <= 200, bool(np.any(np.abs(f[keep] - 700.0) < 0.02))
    (True, True)
    """
    n_max = max(int(n_max), 20)
    if f.size <= n_max:
        return np.arange(f.size)
    n_peaks = 8
    grid = np.geomspace(f[0], f[-1], n_max - 2 * 3 * n_peaks)
    keep = [np.clip(np.searchsorted(f, grid), 0, f.size - 1), [0, f.size - 1]]
    w2 = f**2
    for p in (p1, p2):
        a = np.abs(p) * w2
        peaks = np.flatnonzero((a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])) + 1
        top = peaks[np.argsort(a[peaks])[-n_peaks:]]
        keep.append(np.clip(np.concatenate([top - 1, top, top + 1]), 0, f.size - 1))
    return np.unique(np.concatenate(keep))


class FrfInputError(ValueError):
    """A measured response refused before its fit, and what it blames.

    Parameters
    ----------
    message : str
        The one line that says why.
    key : str
        What is blamed: ``"file"`` (the data) or ``"delay"`` (the delay given); a scenario
        names ``[plant] file`` or ``[plant] delay`` after it.

    Examples
    --------
    >>> err = FrfInputError("1 s turns the phase of the lowest lines ...", "delay")
    >>> err.key, isinstance(err, ValueError)
    ('delay', True)
    """

    def __init__(self, message: str, key: str = "file") -> None:
        super().__init__(message)
        self.key = key


def rigid_body_share(f: NDArray[np.float64], p1: NDArray[np.complex128],
                     p2: NDArray[np.complex128]) -> float:
    """Median of ``-Re P / |P|`` of ``P1`` and ``P2`` over the lowest measured decade: 1 for
    a rigid body ``1/(M s^2)``, the cosine of the median angle of the lines from -180 deg.

    Parameters
    ----------
    f : ndarray
        Frequencies [Hz], increasing.
    p1, p2 : ndarray of complex
        Responses at `f` [m/N].

    Returns
    -------
    float

    Examples
    --------
    >>> import numpy as np
    >>> f = np.geomspace(1.0, 100.0, 30)
    >>> p = -1.0 / (22.5 * (2 * np.pi * f) ** 2)
    >>> rigid_body_share(f, p, p), rigid_body_share(f, -p, -p)
    (1.0, -1.0)
    """
    low = f <= f[0] * 10.0
    q = np.concatenate([p1[low], p2[low]])
    return float(np.median(-q.real / np.abs(q)))


def check_delay(f: NDArray[np.float64], p1: NDArray[np.complex128],
                p2: NDArray[np.complex128], delay: float) -> None:
    """Refuse a given delay [s] that turns lowest lines that are a rigid body into lines
    that are not.

    A measurement chain delays both transfers by ``e^{-s tau}`` with ``tau`` of
    microseconds to milliseconds (sample-and-hold, computation): divided out, it leaves
    the lowest lines the rigid body they are.  A delay that turns them by a large angle
    while they are a rigid body without it (:func:`rigid_body_share` at least
    :data:`RIGID_SHARE_MIN`) is not the data's: 1 s turns the lines of 1-10 Hz by whole
    turns.

    Parameters
    ----------
    f : ndarray
        Frequencies [Hz], increasing.
    p1, p2 : ndarray of complex
        Measured responses at `f` [m/N], the delay not divided out.
    delay : float
        The delay given [s].

    Raises
    ------
    FrfInputError
        With ``key = "delay"``.

    Examples
    --------
    >>> import numpy as np
    >>> f = np.geomspace(1.0, 100.0, 30)
    >>> p = -1.0 / (22.5 * (2 * np.pi * f) ** 2)
    >>> check_delay(f, p, p, 50e-6)                        # microseconds: as it should be
    >>> check_delay(f, p, p, 1.0)
    Traceback (most recent call last):
    ...
    motionhyst.plants.frf_checks.FrfInputError: 1 s turns the phase of the lowest lines \
(1-9.237 Hz) by 360-3325 deg: with it divided out they are no longer a rigid body \
1/(M s^2) (median 76 deg from -180 deg), which they are without it; a measurement chain delays by \
microseconds to milliseconds: is it in seconds? (omit it: the fit estimates the delay)
    """
    if not delay > 0:
        return
    rot = np.exp(1j * TWO_PI * f * delay)
    after = rigid_body_share(f, p1 * rot, p2 * rot)
    if after >= RIGID_SHARE_MIN or rigid_body_share(f, p1, p2) < RIGID_SHARE_MIN:
        return
    top = f[f <= f[0] * 10.0][-1]
    raise FrfInputError(
        f"{delay:g} s turns the phase of the lowest lines ({f[0]:.4g}-{top:.4g} Hz) by "
        f"{360 * f[0] * delay:.4g}-{360 * top * delay:.4g} deg: with it divided out they are "
        f"no longer a rigid body 1/(M s^2) (median {np.degrees(np.arccos(after)):.0f} deg from "
        f"-180 deg), which they are without it; a measurement chain delays by microseconds "
        f"to milliseconds: is it in seconds? (omit it: the fit estimates the delay)", "delay")


def check_transfers_agree(f: NDArray[np.float64], p1: NDArray[np.complex128],
                          p2: NDArray[np.complex128]) -> None:
    """Refuse ``P1`` and ``P2`` that differ by more than :data:`TRANSFER_RATIO_MAX` at the
    lowest lines (up to twice the lowest frequency).

    Below a stage's first mode both are its rigid body ``1/(M s^2)`` (eq. 1): they agree
    to the flexible parts, a few percent.  A factor of 1e3 or 1e6 is one transfer written
    in mm/N or um/N.

    Parameters
    ----------
    f : ndarray
        Frequencies [Hz], increasing.
    p1, p2 : ndarray of complex
        Measured responses at `f` [m/N].

    Raises
    ------
    FrfInputError

    Examples
    --------
    >>> import numpy as np
    >>> f = np.geomspace(1.0, 100.0, 30)
    >>> p = -1.0 / (22.5 * (2 * np.pi * f) ** 2)
    >>> check_transfers_agree(f, p, 1e6 * p)
    Traceback (most recent call last):
    ...
    motionhyst.plants.frf_checks.FrfInputError: P1 and P2 differ by a factor 1e+06 at the \
lowest lines (1-1.887 Hz), where both are the rigid body 1/(M s^2) (M = 22.5 kg from P1, \
2.25e-05 kg from P2): one transfer is in other units (mm/N or um/N for m/N?); check \
p1_abs and p2_abs (or their re, im)
    """
    low = np.flatnonzero(f <= f[0] * _LOWEST_SPAN)
    low = np.arange(min(max(low.size, 3), f.size))
    ratio = float(np.median(np.abs(p1[low]) / np.abs(p2[low])))
    if 1.0 / TRANSFER_RATIO_MAX <= ratio <= TRANSFER_RATIO_MAX:
        return
    w2 = (TWO_PI * f[low]) ** 2
    m1, m2 = (float(np.median(1.0 / (w2 * np.abs(p[low])))) for p in (p1, p2))
    raise FrfInputError(
        f"P1 and P2 differ by a factor {max(ratio, 1 / ratio):.2g} at the lowest lines "
        f"({f[low[0]]:.4g}-{f[low[-1]]:.4g} Hz), where both are the rigid body 1/(M s^2) "
        f"(M = {m1:.3g} kg from P1, {m2:.3g} kg from P2): one transfer is in other units "
        f"(mm/N or um/N for m/N?); check p1_abs and p2_abs (or their re, im)")


def _violation(f: NDArray[np.float64], p1: NDArray[np.complex128],
               taus: NDArray[np.float64]) -> NDArray[np.float64]:
    """Sum over the lines of the positive part of ``Im(P1 e^{s tau}) / |P1|``, squared, for
    each delay of `taus` (in blocks: bounded memory)."""
    out = np.empty(taus.size)
    unit = p1 / np.abs(p1)
    for i in range(0, taus.size, 64):
        t = taus[i:i + 64, None]
        im = (unit[None, :] * np.exp(1j * TWO_PI * f[None, :] * t)).imag
        out[i:i + 64] = np.sum(np.clip(im, 0.0, None) ** 2, axis=1)
    return out


def _passivity_violation(f: NDArray[np.float64], p1: NDArray[np.complex128]) -> float:
    """RMS over the lines of the positive part of ``Im(P1 e^{s tau}) / |P1|`` at the delay
    ``tau >= 0`` that makes it least: 0 for a passive collocated response seen through a
    delay, the noise's share for a measured one."""
    step = _DELAY_STEP_RAD / (TWO_PI * f[-1])
    taus = np.arange(0.0, _DELAY_TURNS * TWO_PI / (TWO_PI * f[-1]), step)
    v = _violation(f, p1, taus)
    i = int(np.argmin(v))
    fine = np.linspace(max(taus[i] - step, 0.0), taus[i] + step, 41)
    return float(np.sqrt(min(v[i], float(np.min(_violation(f, p1, fine)))) / f.size))


def check_phase_sense(f: NDArray[np.float64], p1: NDArray[np.complex128],
                      p2: NDArray[np.complex128] | None = None) -> None:
    """Refuse a collocated ``P1`` whose phases have the opposite sign convention, or that
    is the non-collocated response (``P1`` and ``P2`` swapped).

    The collocated compliance of a passive stage lags: ``Im P1(j w) <= 0`` at every
    frequency (the force does work on the stage), seen through a measurement delay
    ``e^{-s tau}``, ``tau >= 0``, that the phase lags by more.  An analyser set to the
    other convention exports ``P(-j w) = conj P(j w)``: around a mode the phase then
    leads.  Refused when the conjugate of the data is passive within the data's noise and
    with :data:`PHASE_SENSE_RATIO` times less violation than the data (each with the delay
    that suits it best): one mode of negative residue is not a conjugate, nor is data
    that show no mode (only the rigid body), which cannot tell, and pass.  Judged only on
    lowest lines that are a rigid body (a sign flip is refused as such, not as this).
    The non-collocated response lags past -180 deg above its mode, so its conjugate looks
    passive too: where the given ``P2`` is larger than ``P1`` over the top fifth of the
    lines (above its modes the collocated response is the larger: its numerator keeps the
    mass term), the columns are said to be swapped instead (negating the phases would fit
    the swapped data).

    Parameters
    ----------
    f : ndarray
        Frequencies [Hz], increasing.
    p1 : ndarray of complex
        Measured collocated response [m/N].
    p2 : ndarray of complex, optional
        Measured non-collocated response [m/N]: told apart from a swapped ``P1``.

    Raises
    ------
    FrfInputError

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.plants import ModalPlant, TwoMassStage
    >>> f = np.geomspace(1.0, 3000.0, 60)
    >>> p1, _ = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)
    ...                                  ).response(2 * np.pi * f)
    >>> check_phase_sense(f, p1)
    >>> check_phase_sense(f, np.conj(p1))
    Traceback (most recent call last):
    ...
    motionhyst.plants.frf_checks.FrfInputError: the phases have the opposite sign \
convention: P1 leads around its modes (its phase above 0 at lines 342.1-674.3 Hz), where a \
collocated response of a passive stage lags (Im P1 <= 0); the file holds P(-jw) = conj \
P(jw): negate p1_phase_deg and p2_phase_deg (or p1_im and p2_im)

    The two responses swapped:

    >>> p1, p2 = ModalPlant.from_two_mass(TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)
    ...                                   ).response(2 * np.pi * f)
    >>> check_phase_sense(f, p2, p1)
    Traceback (most recent call last):
    ...
    motionhyst.plants.frf_checks.FrfInputError: P1 and P2 look swapped: P1 leads around \
its modes (its phase above 0 at lines ...) and falls below P2 above them, where the \
collocated response of a stage is the larger: put the collocated response in p1_* and the \
non-collocated one in p2_*

    Both conjugated are still a convention:

    >>> check_phase_sense(f, np.conj(p1), np.conj(p2))
    Traceback (most recent call last):
    ...
    motionhyst.plants.frf_checks.FrfInputError: the phases have the opposite sign ...
    """
    if f.size < _PHASE_MIN_LINES or rigid_body_share(f, p1, p1) < RIGID_SHARE_MIN:
        return
    if f.size > MAX_FIT_LINES:  # a dense response: judged on lines thinned as for the fit
        keep = thin_lines(f, p1, p1)
        f, p1 = f[keep], p1[keep]
        p2 = None if p2 is None else p2[keep]
    data, conj = _passivity_violation(f, p1), _passivity_violation(f, np.conj(p1))
    low = p1[f <= f[0] * 10.0]
    noise = max(float(np.sqrt(np.mean((low.imag / np.abs(low)) ** 2))), _PHASE_FLOOR)
    if not (data > PHASE_SENSE_RATIO * conj and conj <= noise):
        return
    lead = f[(p1.imag > 0) & (p1.real > 0)]
    where = (f" (its phase above 0 at lines {lead[0]:.4g}-{lead[-1]:.4g} Hz)" if lead.size
             else "")
    top = f >= f[int(0.8 * (f.size - 1))]
    if p2 is not None and float(np.median(np.abs(p2[top]) / np.abs(p1[top]))) > 1.0:
        raise FrfInputError(
            f"P1 and P2 look swapped: P1 leads around its modes{where} and falls below P2 "
            f"above them, where the collocated response of a stage is the larger: put the "
            f"collocated response in p1_* and the non-collocated one in p2_*")
    raise FrfInputError(
        f"the phases have the opposite sign convention: P1 leads around its modes{where}, "
        f"where a collocated response of a passive stage lags (Im P1 <= 0); the file holds "
        f"P(-jw) = conj P(jw): negate p1_phase_deg and p2_phase_deg (or p1_im and p2_im)")


def check_response(f: NDArray[np.float64], p1: NDArray[np.complex128],
                   p2: NDArray[np.complex128], mass: float | None = None,
                   delay: float | None = None) -> None:
    """Every check of this module, cheapest and most specific first: a given delay, the
    transfers' agreement, the rigid body at the lowest decade (when the mass is fitted),
    the phase sense.

    Parameters
    ----------
    f : ndarray
        Frequencies [Hz], positive and increasing.
    p1, p2 : ndarray of complex
        Measured responses at `f` [m/N], finite and nonzero, the delay not divided out.
    mass : float, optional
        The rigid-body mass when given [kg] (then the rigid body is not checked).
    delay : float, optional
        The delay given [s].

    Raises
    ------
    FrfInputError

    Examples
    --------
    >>> import numpy as np
    >>> f = np.geomspace(1.0, 100.0, 30)
    >>> p = -1.0 / (22.5 * (2 * np.pi * f) ** 2)
    >>> check_response(f, p, p)
    >>> check_response(f, -p, -p)
    Traceback (most recent call last):
    ...
    motionhyst.plants.frf_checks.FrfInputError: the data do not look like a rigid body \
1/(M s^2) at the lowest measured frequencies (Re P > 0); give the mass or check the data
    """
    if delay:
        check_delay(f, p1, p2, delay)
        rot = np.exp(1j * TWO_PI * f * delay)
        p1, p2 = p1 * rot, p2 * rot
    check_transfers_agree(f, p1, p2)
    if mass is None:
        low = f <= f[0] * 10.0
        w2 = (TWO_PI * f[low]) ** 2
        if not float(np.median(np.concatenate([-w2 * p1[low].real, -w2 * p2[low].real]))) > 0:
            raise FrfInputError("the data do not look like a rigid body 1/(M s^2) at the "
                                "lowest measured frequencies (Re P > 0); give the mass or "
                                "check the data")
    check_phase_sense(f, p1, p2)


#: Unit slips of a measured response, and what each makes of a fitted plant: the factor
#: the response is ``c`` times the true one, the frequencies ``a`` times the true ones.
UNIT_SLIPS = (
    (1e3, 1.0, "a response in mm/N read as m/N"),
    (1e6, 1.0, "a response in um/N read as m/N"),
    (1e-3, 1.0, "a response 1e3 times too small"),
    (1.0, TWO_PI, "frequencies in rad/s read as Hz"),
    (1.0, 1.0 / TWO_PI, "frequencies 2 pi times too low"),
    (1.0, 1e-3, "frequencies in kHz read as Hz"),
    (1.0, 1e3, "frequencies in mHz read as Hz"),
)


def unit_slip_plants(plant):
    """The fitted plant each slip of :data:`UNIT_SLIPS` would make the true one: with the
    response ``c`` times and the frequencies ``a`` times the true ones, the true plant is
    ``P(s) = P_fit(a s) / c``, ``M a^2 c``, modes at ``w / a`` with residues
    ``r / (a^2 c)``.

    Parameters
    ----------
    plant : ModalPlant
        A plant fitted to the data (:func:`motionhyst.plants.frf_fit.fit_frf`).

    Returns
    -------
    list of (str, ModalPlant)
        The slip, and the plant the data would give without it.

    Examples
    --------
    >>> from motionhyst.plants import ModalPlant, Mode
    >>> fitted = ModalPlant(22.5e-3, [Mode(694.3, 0.00265, 155.6, 44.4)])   # mm/N data
    >>> slip, true = unit_slip_plants(fitted)[0]
    >>> slip, round(true.M, 6), round(true.modes[0].r1, 4)
    ('a response in mm/N read as m/N', 22.5, 0.1556)
    """
    from motionhyst.plants.modal import ModalPlant, Mode

    return [(what, ModalPlant(plant.M * a * a * c,
                              [Mode(m.frequency_hz / a, m.damping, m.r1 / (a * a * c),
                                    m.r2 / (a * a * c)) for m in plant.modes],
                              source=plant.source))
            for c, a, what in UNIT_SLIPS]
