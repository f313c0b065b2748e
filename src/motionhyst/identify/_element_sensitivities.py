"""The derivatives an element link's sensitivities need in the link's own parameters.

:func:`motionhyst.time.openloop.simulate_elements` runs the open loop with a link
of exact-update elements and, when asked, the forward sensitivities of its
output: the derivatives of the stage's discrete matrices in its parameters
(:meth:`~motionhyst.plants.mechanics.Mechanics.foh`, Frechet derivatives of the matrix
exponential), the partial derivatives of each element's update in its state,
its displacement and its parameters
(:func:`~motionhyst.hysteresis.stepping.advance_partials`), and the implicit
link force through ``dw = (dW_rest + W_dx d(base)) / (1 + W_dx B1)``.  What
it needs besides is how the elements' parameters (the rows of the link's
:class:`~motionhyst.hysteresis.stepping.Stepping`) move with the link model's
parameters: :func:`row_derivatives`, so that a registered model needs nothing
more for an exact Jacobian.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from motionhyst.hysteresis.stepping import DIFFERENTIATED, N_PARAMS


def row_derivatives(build, values: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """``d params[j, l] / d values[b]`` of the link's stepping rows, by central differences.

    The rows are algebraic in the model's parameters (copies, products,
    ratios, a reordering), so central differences with a relative step of
    ``1e-5`` are exact to about ``1e-10``.  None if an element kind is not
    differentiated (:data:`~motionhyst.hysteresis.stepping.DIFFERENTIATED`)
    or the rows change shape.

    Examples
    --------
    A Dahl link's row is ``(k / fc, fc, alpha)``:

    >>> import numpy as np
    >>> from motionhyst.hysteresis import Dahl
    >>> d = row_derivatives(lambda v: Dahl(k=v[0], fc=v[1], alpha=v[2]),
    ...                     np.array([2e4, 10.0, 1.0]))
    >>> np.round(d[0, :3, 1], 6).tolist()      # d(k / fc, fc, alpha) / d fc
    [-200.0, 1.0, 0.0]
    """
    st = build(values).time_stepping()
    if not np.all(np.isin(st.codes, DIFFERENTIATED)):
        return None
    m = st.codes.size
    out = np.zeros((m, N_PARAMS, values.size))
    for b in range(values.size):
        step = 1e-5 * abs(values[b]) if values[b] != 0.0 else 1e-8
        hi, lo = values.copy(), values.copy()
        hi[b] += step
        lo[b] = max(lo[b] - step, 0.0) if values[b] >= 0 else lo[b] - step
        try:
            p_hi = build(hi).time_stepping().params
            p_lo = build(lo).time_stepping().params
        except ValueError:
            return None
        if p_hi.shape != st.params.shape or p_lo.shape != st.params.shape:
            return None
        out[:, :, b] = (p_hi - p_lo) / (hi[b] - lo[b])
    return out
