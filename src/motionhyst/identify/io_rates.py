"""A record's rates: Savitzky-Golay derivatives of its sampled position, with numpy alone.

A cubic fitted by least squares to each window of samples gives the velocity and the
acceleration at the window's centre (a convolution with fixed weights); the first and
last half windows take the derivative of the cubic fitted to the first and last whole
window (as :func:`scipy.signal.savgol_filter` with ``mode="interp"``, to round-off).
numpy alone: a record's inverse-dynamics check
(:func:`~motionhyst.identify.io_checks.check_inertia`) imports neither scipy.signal nor
the fit engines, so that a record without inertia is refused at once (the fits' start
keeps scipy's filter, and its numbers).

Examples
--------
>>> import numpy as np
>>> t = np.arange(100) * 0.01
>>> a = savgol_derivative(t ** 3, window=7, deriv=2, delta=0.01)   # a cubic: exact
>>> bool(np.allclose(a, 6.0 * t))
True
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["savgol_derivative"]


def savgol_derivative(y: ArrayLike, window: int, deriv: int, delta: float, order: int = 3
                      ) -> NDArray[np.float64]:
    """The `deriv`-th derivative of the samples `y` by a Savitzky-Golay filter.

    Parameters
    ----------
    y : array_like
        Samples at the spacing `delta`, at least `window` of them.
    window : int
        Samples of the filter, odd, > `order`.
    deriv : int
        The derivative: 1 the rate, 2 the acceleration.
    delta : float
        The sample spacing [s].
    order : int
        The polynomial's order (3: a cubic).

    Returns
    -------
    ndarray
        The derivative at each sample.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(50) * 0.1
    >>> v = savgol_derivative(2.0 * t ** 2, window=5, deriv=1, delta=0.1)
    >>> bool(np.allclose(v, 4.0 * t))                       # also at the ends
    True
    """
    x = np.asarray(y, dtype=float)
    half = window // 2
    pos = np.arange(-half, window - half, dtype=float)[::-1]  # the convolution's order
    rhs = np.zeros(order + 1)
    rhs[deriv] = math.factorial(deriv) / delta ** deriv
    weights = np.linalg.lstsq(pos ** np.arange(order + 1).reshape(-1, 1), rhs, rcond=None)[0]
    out = np.convolve(x, weights)[half:half + x.size]
    t = np.arange(window, dtype=float)
    for first, keep in ((0, slice(0, half)), (x.size - window, slice(window - half, window))):
        cubic = np.polyder(np.polyfit(t, x[first:first + window], order), deriv)
        out[first + keep.start:first + keep.stop] = np.polyval(cubic, t[keep]) / delta ** deriv
    return out
