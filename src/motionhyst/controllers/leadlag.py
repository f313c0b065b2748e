"""Feedback controller of the paper's eq. (23), and the loop's bandwidth."""

from __future__ import annotations

import control
import numpy as np
from scipy.optimize import brentq

from motionhyst.controllers.characteristic import leadlag_coefficients
from motionhyst.core.lti import TWO_PI, freqresp
from motionhyst.hysteresis.base import check_positive

__all__ = ["LeadLagLowpass", "bandwidth"]


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
    >>> from motionhyst.controllers.leadlag import bandwidth
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
        super().__init__(*leadlag_coefficients(self.K, self.f1, self.f2, self.flp, self.beta))

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

    Examples
    --------
    >>> from motionhyst import LeadLagLowpass, TwoMassStage
    >>> C = LeadLagLowpass(K=6.2e6, f1=60.0, f2=240.0, flp=700.0, beta=0.6)
    >>> round(bandwidth(C, TwoMassStage(m1=5.0, m2=17.5, b=90.0, k=7.4e7).P2), 2)
    120.65
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
