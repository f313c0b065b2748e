"""Plants known only by measured frequency responses of ``P1`` and ``P2``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.validation import check_positive
from motionhyst.plants.base import FixedPlant
from motionhyst.plants.registry import register

if TYPE_CHECKING:  # the readers (pandas, scipy.io) are imported when a file is read
    from motionhyst.io.csvdata import Source

__all__ = ["BOTH_SETS_RTOL", "FRD_LINE_BYTES", "FrdData", "MeasuredPlant", "frd_plant",
           "load_frd_plant", "read_frd"]

TWO_PI = 2.0 * np.pi


@register
@dataclass(frozen=True)
class MeasuredPlant(FixedPlant):
    """A plant known only by measured frequency responses of ``P1`` and ``P2``.

    Attributes
    ----------
    P1, P2 : control.FrequencyResponseData
        Collocated and non-collocated transfers [m/N].
    M : float
        Rigid-body mass [kg] of the feedforward ``M s^2``.
    source : str
        Where the data came from.
    resolution : float or None
        Relative scatter of the data (RMS of ``|P - P_smooth| / |P|``), the
        smallest relative difference the data resolve; None if unknown.
        ``Pf2 = Pr - P2`` is resolved only where ``|Pf2| / |P2|`` exceeds it.

    Examples
    --------
    >>> import control
    >>> import numpy as np
    >>> from motionhyst import MeasuredPlant, TwoMassStage
    >>> stage = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)
    >>> omega = 2 * np.pi * np.geomspace(1.0, 1000.0, 100)
    >>> plant = MeasuredPlant(P1=control.frd(stage.P1, omega), P2=control.frd(stage.P2, omega),
    ...                       M=stage.M, source="Table I, sampled")
    >>> plant.frequency_range_hz
    (1.0, 1000.0...)
    """

    P1: Any
    P2: Any
    M: float
    source: str = ""
    resolution: float | None = None

    name: ClassVar[str] = "frd"
    output: ClassVar[str] = "y2"
    is_lti: ClassVar[bool] = False
    force_offset: ClassVar[float] = 0.0
    Pf2: ClassVar[None] = None  # Pr - P2 from the data
    pf2_static: ClassVar[None] = None  # eq. (21) needs a model of the modes
    no_parameters: ClassVar[str] = "a measured plant has no parameters to set"
    no_state_space: ClassVar[str] = (
        "a measured plant (frequency-response data) has no state-space form; "
        'fit a model to it ([plant] use = "fit")'
    )

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        """The measured frequencies [Hz]."""
        return np.asarray(self.P2.omega, dtype=float) / TWO_PI

    def measured_line(self, frequency_hz: float, rtol: float = 1e-9) -> float | None:
        """The measured frequency equal to `frequency_hz` (to `rtol`), else None.

        Parameters
        ----------
        frequency_hz : float
            A frequency [Hz].
        rtol : float
            Relative tolerance of the match.
        """
        f = self.frequency_hz
        i = int(np.argmin(np.abs(f - frequency_hz)))
        return float(f[i]) if abs(f[i] - frequency_hz) <= rtol * frequency_hz else None

    @property
    def Pr(self) -> Any:
        """Rigid-body model ``1 / (M s^2)``."""
        import control

        return control.tf([1.0], [self.M, 0.0, 0.0])

    @property
    def frequency_range_hz(self) -> tuple[float, float]:
        """Lowest and highest measured frequency [Hz]."""
        w = self.P2.omega
        return float(w.min() / TWO_PI), float(w.max() / TWO_PI)

    def to_dict(self) -> dict:
        """``type``, the rigid-body mass, the source and the measured range."""
        lo, hi = self.frequency_range_hz
        return {"type": self.name, "M": self.M, "source": self.source,
                "frequency_range_hz": [lo, hi]}


_FRD_COLUMNS = {
    "reim": ("p1_re", "p1_im", "p2_re", "p2_im"),
    "absphase": ("p1_abs", "p1_phase_deg", "p2_abs", "p2_phase_deg"),
}


def _first_out_of_order(f: NDArray[np.float64]) -> str:
    """What is wrong with the first frequency that is not positive or does not increase, and
    the remedy."""
    bad = np.flatnonzero(f <= 0)
    if bad.size:
        return f"{f[bad[0]]:g} Hz at line {bad[0] + 1} of the data"
    i = int(np.flatnonzero(np.diff(f) <= 0)[0])
    if f[i + 1] == f[i]:
        return (f"{f[i]:g} Hz is given twice (lines {i + 1} and {i + 2} of the data); keep one "
                f"line for each frequency")
    return (f"{f[i + 1]:g} Hz follows {f[i]:g} Hz (line {i + 2} of the data); sort the lines "
            f"by frequency")


#: Largest relative difference of the two column sets of one file, line by line, for them
#: to be one measurement written twice (their rounding: 7 digits, 1e-4 deg, is far below).
BOTH_SETS_RTOL = 1e-3


@dataclass(frozen=True)
class FrdData:
    """A measured response as read, before python-control holds it (:func:`read_frd`).

    Attributes
    ----------
    frequency_hz : ndarray
        Frequencies [Hz], positive and increasing.
    P1, P2 : ndarray of complex
        Collocated and non-collocated responses [m/N].
    M : float
        Rigid-body mass [kg]: given, or estimated from the lowest decade.
    source : str
        The file, as messages name it.

    Examples
    --------
    >>> import numpy as np
    >>> f = np.array([1.0, 2.0])
    >>> p = -1.0 / (22.5 * (2 * np.pi * f) ** 2) + 0j
    >>> FrdData(f, p, p, 22.5, "sampled").M
    22.5
    """

    frequency_hz: NDArray[np.float64]
    P1: NDArray[np.complex128]
    P2: NDArray[np.complex128]
    M: float
    source: str


def _both_sets(where: str, f, data: NDArray[np.float64]) -> None:
    """Refuse a file whose re, im and abs, phase columns (both given) disagree."""
    p1 = data[:, 1] + 1j * data[:, 2]
    p2 = data[:, 3] + 1j * data[:, 4]
    for name, p, col in (("P1", p1, 5), ("P2", p2, 7)):
        q = data[:, col] * np.exp(1j * np.deg2rad(data[:, col + 1]))
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = np.abs(p - q) / np.maximum(np.abs(p), np.abs(q))
        rel[~np.isfinite(rel)] = np.inf
        i = int(np.argmax(rel))
        if rel[i] > BOTH_SETS_RTOL:
            n = name.lower()
            raise ValueError(
                f"{where}: has both {n}_re, {n}_im and {n}_abs, {n}_phase_deg, and they "
                f"disagree: {name} = {_num(p[i])} against {_num(q[i])} at {f[i]:g} Hz "
                f"(line {i + 1}); keep one set (the other may be in other units or a "
                f"conjugate)")


def _num(p: complex) -> str:
    return f"{abs(p):.4g} m/N at {np.degrees(np.angle(p)):.4g} deg"


def read_frd(path: Source, mass: float | None = None) -> FrdData:
    """Read and check a measured response as :func:`load_frd_plant` does, without building
    the plant (python-control is not loaded): what a fit of it needs.

    A file with both column sets (``p1_re, ...`` and ``p1_abs, ...``) is read when they
    agree to :data:`BOTH_SETS_RTOL` at every line, else refused.

    Parameters
    ----------
    path : str, Path or DataFrame
        As for :func:`load_frd_plant`.
    mass : float, optional
        As for :func:`load_frd_plant`.

    Returns
    -------
    FrdData

    Raises
    ------
    ValueError
        One line naming the file.

    Examples
    --------
    >>> import numpy as np
    >>> import pandas as pd
    >>> f = np.array([1.0, 2.0, 4.0])
    >>> p = -1.0 / (22.5 * (2 * np.pi * f) ** 2)
    >>> data = read_frd(pd.DataFrame({"frequency_hz": f, "p1_re": p, "p1_im": 0 * f,
    ...                               "p2_re": p, "p2_im": 0 * f}))
    >>> round(data.M, 6), data.P1.dtype
    (22.5, dtype('complex128'))
    """
    from motionhyst.io.csvdata import describe
    from motionhyst.io.records import check_unread, read_record, record_columns

    where = describe(path)
    names = record_columns(path)
    header = set(names)
    expected = (f"{', '.join(_FRD_COLUMNS['reim'])} or {', '.join(_FRD_COLUMNS['absphase'])}"
                f" next to frequency_hz (found {','.join(names) or 'none'})")
    if "frequency_hz" not in header:
        raise ValueError(f"{where}: missing column 'frequency_hz'; need columns {expected}")
    kinds = [k for k, cols in _FRD_COLUMNS.items() if set(cols) <= header]
    if not kinds:
        raise ValueError(f"{where}: need columns {expected}")
    cols = ("frequency_hz", *(c for k in kinds for c in _FRD_COLUMNS[k]))
    check_unread([path], cols, _check_lines)  # a long file
    data = read_record(path, cols)
    _check_lines([len(data)])
    if not np.all(np.isfinite(data)):
        raise ValueError(f"{where}: non-finite value in data")
    f = data[:, 0].copy()
    if np.any(f <= 0) or np.any(np.diff(f) <= 0):
        raise ValueError(f"{where}: frequency_hz must be positive and increasing: "
                         f"{_first_out_of_order(f)}")
    if len(f) < 2:
        raise ValueError(f"{where}: need at least two frequencies")
    if len(kinds) == 2:
        _both_sets(where, f, data)
    if kinds[0] == "reim":  # filled in place: no temporary of the whole response
        p1, p2 = np.empty(len(f), complex), np.empty(len(f), complex)
        p1.real, p1.imag, p2.real, p2.imag = data[:, 1], data[:, 2], data[:, 3], data[:, 4]
    else:
        for col, name in ((1, "p1_abs"), (3, "p2_abs")):
            bad = np.flatnonzero(data[:, col] <= 0)
            if bad.size:
                raise ValueError(f"{where}: {name} must be > 0 (a magnitude; a sign belongs in "
                                 f"the phase), got {data[bad[0], col]:g} at "
                                 f"{f[bad[0]]:g} Hz")
        p1 = data[:, 1] * np.exp(1j * np.deg2rad(data[:, 2]))
        p2 = data[:, 3] * np.exp(1j * np.deg2rad(data[:, 4]))
    del data
    if mass is None:
        low = f <= f[0] * 10
        mass = float(np.median(-1.0 / ((TWO_PI * f[low]) ** 2 * p2[low].real)))
        if not np.isfinite(mass) or mass <= 0:
            raise ValueError(f"{where}: cannot estimate the rigid-body mass: -1/(omega^2 Re P2) "
                             f"over the lowest decade is {mass:.3g} kg, not a mass (phases in "
                             f"radians, or a sign?); check the data or give [plant] mass")
    mass = check_positive("mass", mass)
    return FrdData(f, p1, p2, mass, where)


def load_frd_plant(path: Source, mass: float | None = None) -> MeasuredPlant:
    """Read a measured plant from CSV or MATLAB ``.mat`` (or a DataFrame with the same columns).

    The file has a column (a MATLAB file: a vector variable) ``frequency_hz``, plus either
    ``p1_re, p1_im, p2_re, p2_im`` or ``p1_abs, p1_phase_deg, p2_abs,
    p2_phase_deg`` (magnitudes in m/N, phases in degrees); both sets only where they agree
    (:func:`read_frd`).

    Parameters
    ----------
    path : str, Path or DataFrame
        CSV file (BOM, comma or semicolon, names in any case) or MATLAB file
        (levels 4 to 7.3), read by :func:`motionhyst.io.records.read_record`;
        or a DataFrame with those columns.
    mass : float, optional
        Rigid-body mass [kg]; if omitted, estimated from the lowest measured
        decade as the median of ``-1 / (omega^2 Re P2)``.

    Returns
    -------
    MeasuredPlant

    Examples
    --------
    Write the Table I stage's responses as a measurement would give them, and read them back:

    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from motionhyst import TwoMassStage, load_frd_plant
    >>> stage = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)
    >>> f = np.geomspace(1.0, 2000.0, 300)
    >>> p1, p2 = stage.P1(2j * np.pi * f), stage.P2(2j * np.pi * f)
    >>> path = Path(tempfile.mkdtemp()) / "plant.csv"
    >>> np.savetxt(path, np.column_stack([f, p1.real, p1.imag, p2.real, p2.imag]),
    ...            delimiter=",", header="frequency_hz,p1_re,p1_im,p2_re,p2_im", comments="")
    >>> plant = load_frd_plant(path)
    >>> print(f"M = {plant.M:.3f} kg")                    # estimated from the lowest decade
    M = 22.500 kg
    >>> plant.frequency_range_hz
    (1.0, 2000.0...)
    """
    return frd_plant(read_frd(path, mass))


def frd_plant(data: FrdData) -> MeasuredPlant:
    """The :class:`MeasuredPlant` of a response read by :func:`read_frd` (python-control's
    frequency-response data, with their splines).

    Parameters
    ----------
    data : FrdData
        The response read.

    Returns
    -------
    MeasuredPlant

    Examples
    --------
    >>> import numpy as np
    >>> f = np.geomspace(1.0, 100.0, 5)
    >>> p = -1.0 / (22.5 * (2 * np.pi * f) ** 2) + 0j
    >>> frd_plant(FrdData(f, p, p, 22.5, "sampled")).frequency_range_hz
    (1.0, 100.0...)
    """
    import control  # once the data are read and checked: a refusal does not wait for it

    omega = TWO_PI * data.frequency_hz
    smooth = len(omega) > 3
    P1 = control.frd(data.P1, omega, smooth=smooth)
    P2 = control.frd(data.P2, omega, smooth=smooth)
    return MeasuredPlant(P1=P1, P2=P2, M=data.M, source=data.source)


FRD_LINE_BYTES = 400
"""Memory :func:`load_frd_plant` takes per line of a measured response [bytes]: its values
read (:func:`~motionhyst.io.csvdata.reading_bytes`), the two complex responses and each
one's interpolating spline (python-control's ``smooth``) while it is made.  Measured, address
space above a warmed process: 1e5 and 1e6 lines of re, im columns 20 and 372 MB (resident
14 and 281 MB)."""


def _check_lines(lines: list[int]) -> None:
    """Refuse a measured response of more lines than :data:`FRD_LINE_BYTES` each fit the
    memory budget."""
    from motionhyst.core.budget import check_memory

    check_memory(FRD_LINE_BYTES * float(lines[0]), f"a measured plant of {lines[0]} lines "
                 f"(its responses and their splines)", "give fewer lines (a measurement "
                 "thinned to the lines that resolve the plant: a few hundred log-spaced)")
