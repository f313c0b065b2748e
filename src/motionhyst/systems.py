"""Linear parts of the loop: two-mass stage (eqs. 1-2), controller (eq. 23), measured plants.

All objects are python-control systems, so any other python-control LTI
plant or controller can take their place, and a plant may also be given as
measured frequency-response data (:func:`load_frd_plant`).
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

from motionhyst.csvdata import Source, describe
from motionhyst.hysteresis.base import check_positive
from motionhyst.io.records import read_record, record_columns

TWO_PI = 2.0 * np.pi


def freqresp(sys, omega: ArrayLike) -> NDArray[np.complex128]:
    """Complex frequency response of a SISO python-control system at `omega` [rad/s].

    Works for transfer functions, state-space systems and frequency-response
    data (interpolated between measured points).
    """
    w = np.atleast_1d(np.asarray(omega, dtype=float))
    if isinstance(sys, control.FrequencyResponseData):
        return np.asarray(sys.eval(w, squeeze=True), dtype=complex).reshape(w.shape)
    if isinstance(sys, control.StateSpace):
        sys = control.ss2tf(sys)
    if isinstance(sys, control.TransferFunction):
        num = np.asarray(sys.num_array[0, 0], dtype=float) if hasattr(sys, "num_array") else \
            np.asarray(sys.num[0][0], dtype=float)
        den = np.asarray(sys.den_array[0, 0], dtype=float) if hasattr(sys, "den_array") else \
            np.asarray(sys.den[0][0], dtype=float)
        s = 1j * w
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.polyval(num, s) / np.polyval(den, s)
    raise TypeError(f"unsupported system type {type(sys).__name__}")


class TwoMassStage:
    """Floating two-mass stage of the paper's Fig. 2, eqs. (1)-(2).

    Mass `m1` is actuated (position ``y1``, where the dynamic link acts), mass
    `m2` carries the point of control (position ``y2``); they are connected
    by a spring `k` and damper `b`.

    Parameters
    ----------
    m1, m2 : float
        Masses [kg], > 0.
    b : float
        Internal damping [N s/m], >= 0.
    k : float
        Internal stiffness [N/m], > 0.

    Attributes
    ----------
    M : float
        Total mass ``m1 + m2`` [kg].

    Examples
    --------
    >>> from motionhyst import TwoMassStage
    >>> stage = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)   # Table I
    >>> stage.M
    22.5
    >>> round(stage.resonance_hz, 1)
    694.3
    >>> import numpy as np
    >>> s = 2j * np.pi * 10.0                  # 10 Hz, far below the resonance
    >>> print(f"{abs(stage.P1(s) / stage.Pr(s)):.4f}")   # P1, Pr: control.TransferFunction
    0.9993
    """

    def __init__(self, m1: float, m2: float, b: float, k: float) -> None:
        self.m1 = check_positive("m1", m1)
        self.m2 = check_positive("m2", m2)
        self.k = check_positive("k", k)
        b = float(b)
        if not np.isfinite(b) or b < 0:
            raise ValueError(f"b must be finite and >= 0, got {b!r}")
        self.b = b
        self.M = self.m1 + self.m2

    def __repr__(self) -> str:
        return f"TwoMassStage(m1={self.m1}, m2={self.m2}, b={self.b}, k={self.k})"

    @property
    def _flex_den(self) -> list[float]:
        M = self.M
        return [M * self.m1 * self.m2, M * self.b * M, M * self.k * M]

    @property
    def Pr(self) -> control.TransferFunction:
        """Rigid-body dynamics ``1 / (M s^2)``, eq. (1)."""
        return control.tf([1.0], [self.M, 0.0, 0.0])

    @property
    def Pf1(self) -> control.TransferFunction:
        """Flexible part of the collocated transfer, eq. (2)."""
        return control.tf([self.m2**2], self._flex_den)

    @property
    def Pf2(self) -> control.TransferFunction:
        """Flexible part of the non-collocated transfer, eq. (2)."""
        return control.tf([self.m1 * self.m2], self._flex_den)

    @property
    def P1(self) -> control.TransferFunction:
        """Collocated transfer ``y1 / (u - w) = Pr + Pf1``, eq. (1)."""
        m1, m2, b, k = self.m1, self.m2, self.b, self.k
        return control.tf([m2, b, k], [m1 * m2, b * self.M, k * self.M, 0.0, 0.0])

    @property
    def P2(self) -> control.TransferFunction:
        """Non-collocated transfer ``y2 / (u - w) = Pr - Pf2``, eq. (1)."""
        b, k = self.b, self.k
        return control.tf([b, k], [self.m1 * self.m2, b * self.M, k * self.M, 0.0, 0.0])

    @property
    def resonance_hz(self) -> float:
        """Undamped frequency of the internal mode, ``sqrt(k M / (m1 m2)) / (2 pi)`` [Hz]."""
        return float(np.sqrt(self.k * self.M / (self.m1 * self.m2)) / TWO_PI)

    def ss(self) -> control.StateSpace:
        """State-space form, state ``(y1, y2, y1', y2')``, input ``u - w``, outputs ``(y1, y2)``."""
        m1, m2, b, k = self.m1, self.m2, self.b, self.k
        A = [[0, 0, 1, 0], [0, 0, 0, 1], [-k / m1, k / m1, -b / m1, b / m1],
             [k / m2, -k / m2, b / m2, -b / m2]]
        B = [[0], [0], [1 / m1], [0]]
        C = [[1, 0, 0, 0], [0, 1, 0, 0]]
        return control.ss(A, B, C, [[0], [0]], inputs="f", outputs=["y1", "y2"])

    def to_dict(self) -> dict:
        """Parameters as a JSON-ready dictionary."""
        return {"m1": self.m1, "m2": self.m2, "b": self.b, "k": self.k}


class LeadLagLowpass(control.TransferFunction):
    """Feedback controller of eq. (23): lead-lag filter times second-order low-pass.

    ``C(s) = K (f2/f1) (s + 2 pi f1) / (s + 2 pi f2)
    * (2 pi flp)^2 / (s^2 + 4 beta pi flp s + (2 pi flp)^2)``

    A python-control transfer function; the parameters are kept as attributes.

    Parameters
    ----------
    K : float
        Gain [N/m], > 0.
    f1, f2 : float
        Zero and pole of the lead filter [Hz], > 0.
    flp : float
        Low-pass corner [Hz], > 0.
    beta : float
        Low-pass damping ratio [-], > 0.

    Examples
    --------
    >>> from motionhyst import LeadLagLowpass, TwoMassStage
    >>> from motionhyst.systems import bandwidth
    >>> C = LeadLagLowpass(K=6.2e6, f1=60.0, f2=240.0, flp=700.0, beta=0.6)   # Table I
    >>> C.K, C.flp
    (6200000.0, 700.0)
    >>> stage = TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7)
    >>> print(f"{bandwidth(C, stage.P2):.1f} Hz")
    120.6 Hz
    """

    def __init__(self, K: float, f1: float, f2: float, flp: float, beta: float) -> None:
        self.K = check_positive("K", K)
        self.f1 = check_positive("f1", f1)
        self.f2 = check_positive("f2", f2)
        self.flp = check_positive("flp", flp)
        self.beta = check_positive("beta", beta)
        w1, w2, wl = TWO_PI * self.f1, TWO_PI * self.f2, TWO_PI * self.flp
        num = np.polymul([1.0, w1], [self.K * (self.f2 / self.f1) * wl**2])
        den = np.polymul([1.0, w2], [1.0, 2.0 * self.beta * wl, wl**2])
        super().__init__(num, den)

    def to_dict(self) -> dict:
        """Parameters as a JSON-ready dictionary."""
        return {"type": "leadlag-lowpass", "K": self.K, "f1": self.f1, "f2": self.f2,
                "flp": self.flp, "beta": self.beta}


def bandwidth(controller, plant, f_min: float = 1e-3, f_max: float = 1e6) -> float:
    """First 0 dB crossing of the open loop ``L = C P2`` [Hz].

    Parameters
    ----------
    controller, plant : python-control system
        ``C`` and the non-collocated plant ``P2`` (LTI or frequency data).
    f_min, f_max : float
        Search range [Hz].

    Returns
    -------
    float
        Lowest frequency where ``|C P2|`` falls through 1, or ``nan`` if it
        does not within the range.
    """
    if isinstance(plant, control.FrequencyResponseData):
        f_min = max(f_min, plant.omega.min() / TWO_PI)
        f_max = min(f_max, plant.omega.max() / TWO_PI)
    f = np.geomspace(f_min, f_max, 4000)

    def logmag(fr):
        return np.log(np.abs(freqresp(controller, TWO_PI * fr) * freqresp(plant, TWO_PI * fr)))

    g = logmag(f)
    idx = np.nonzero((g[:-1] > 0) & (g[1:] <= 0))[0]
    if idx.size == 0:
        return float("nan")
    i = idx[0]
    return float(brentq(lambda x: float(logmag(np.array([x]))[0]), f[i], f[i + 1], xtol=1e-12))


@dataclass(frozen=True)
class MeasuredPlant:
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

    P1: control.FrequencyResponseData
    P2: control.FrequencyResponseData
    M: float
    source: str = ""
    resolution: float | None = None

    @property
    def frequency_hz(self) -> NDArray[np.float64]:
        """The measured frequencies [Hz]."""
        return np.asarray(self.P2.omega, dtype=float) / TWO_PI

    def measured_line(self, frequency_hz: float, rtol: float = 1e-9) -> float | None:
        """The measured frequency equal to `frequency_hz` (to `rtol`), else None."""
        f = self.frequency_hz
        i = int(np.argmin(np.abs(f - frequency_hz)))
        return float(f[i]) if abs(f[i] - frequency_hz) <= rtol * frequency_hz else None

    @property
    def Pr(self) -> control.TransferFunction:
        """Rigid-body model ``1 / (M s^2)``."""
        return control.tf([1.0], [self.M, 0.0, 0.0])

    @property
    def frequency_range_hz(self) -> tuple[float, float]:
        """Lowest and highest measured frequency [Hz]."""
        w = self.P2.omega
        return float(w.min() / TWO_PI), float(w.max() / TWO_PI)


_FRD_COLUMNS = {
    "reim": ("p1_re", "p1_im", "p2_re", "p2_im"),
    "absphase": ("p1_abs", "p1_phase_deg", "p2_abs", "p2_phase_deg"),
}


def load_frd_plant(path: Source, mass: float | None = None) -> MeasuredPlant:
    """Read a measured plant from CSV or MATLAB ``.mat`` (or a DataFrame with the same columns).

    The file has a column (a MATLAB file: a vector variable) ``frequency_hz``, plus either
    ``p1_re, p1_im, p2_re, p2_im`` or ``p1_abs, p1_phase_deg, p2_abs,
    p2_phase_deg`` (magnitudes in m/N, phases in degrees).

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
    where = describe(path)
    names = record_columns(path)
    header = set(names)
    expected = (f"{', '.join(_FRD_COLUMNS['reim'])} or {', '.join(_FRD_COLUMNS['absphase'])}"
                f" next to frequency_hz (found {','.join(names) or 'none'})")
    if "frequency_hz" not in header:
        raise ValueError(f"{where}: missing column 'frequency_hz'; need columns {expected}")
    kind = next((k for k, cols in _FRD_COLUMNS.items() if set(cols) <= header), None)
    if kind is None:
        raise ValueError(f"{where}: need columns {expected}")
    data = read_record(path, ("frequency_hz", *_FRD_COLUMNS[kind]))
    if not np.all(np.isfinite(data)):
        raise ValueError(f"{where}: non-finite value in data")
    f = data[:, 0]
    if np.any(f <= 0) or np.any(np.diff(f) <= 0):
        raise ValueError(f"{where}: frequency_hz must be positive and increasing")
    if len(f) < 2:
        raise ValueError(f"{where}: need at least two frequencies")
    if kind == "reim":
        p1 = data[:, 1] + 1j * data[:, 2]
        p2 = data[:, 3] + 1j * data[:, 4]
    else:
        p1 = data[:, 1] * np.exp(1j * np.deg2rad(data[:, 2]))
        p2 = data[:, 3] * np.exp(1j * np.deg2rad(data[:, 4]))
    omega = TWO_PI * f
    if mass is None:
        low = f <= f[0] * 10
        mass = float(np.median(-1.0 / (omega[low] ** 2 * p2[low].real)))
        if not np.isfinite(mass) or mass <= 0:
            raise ValueError(f"{where}: cannot estimate the rigid-body mass; give it explicitly")
    mass = check_positive("mass", mass)
    P1 = control.frd(p1, omega, smooth=len(f) > 3)
    P2 = control.frd(p2, omega, smooth=len(f) > 3)
    return MeasuredPlant(P1=P1, P2=P2, M=mass, source=where)
