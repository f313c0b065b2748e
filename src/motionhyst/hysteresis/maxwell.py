"""Maxwell-slip element: Jenkins elements in parallel (a Prandtl-Ishlinskii structure).

A cable slab slips in many places at different forces; parallel Jenkins
elements ``(k_i, fc_i)`` capture that.  Every property is the sum of the
elements': the force, the describing function (eq. 10 per element), the
higher-order describing functions and the exact periodic output.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.hysteresis.base import Hysteresis, check_amplitudes, check_positive
from motionhyst.hysteresis.jenkins import Jenkins, jenkins_describing_function
from motionhyst.hysteresis.registry import Parameter, register
from motionhyst.hysteresis.stepping import STOP, Stepping

__all__ = ["MaxwellSlip"]


@register
class MaxwellSlip(Hysteresis):
    """Parallel Jenkins elements with stiffnesses `k` and slip forces `fc`.

    Parameters
    ----------
    k : array_like
        Spring stiffnesses ``k_i`` [N/m], each > 0.
    fc : array_like
        Slip forces ``fc_i`` [N], each > 0, same length as `k`.

    Notes
    -----
    The link's parameters are fixed once it is made: :attr:`k` and :attr:`fc` are read-only
    arrays (a link with other elements is a new link), so that what is derived from them
    (the elements in slip order, :meth:`periodic_stops`) is derived once.

    Examples
    --------
    >>> from motionhyst.hysteresis import MaxwellSlip
    >>> link = MaxwellSlip(k=[1.0, 2.0], fc=[1.0, 0.5])
    >>> link.initial_stiffness
    3.0
    >>> link.k[0] = 5.0
    Traceback (most recent call last):
    ...
    ValueError: assignment destination is read-only
    """

    name = "maxwell-slip"
    rate_independent = True
    parameters = (Parameter("k", "N/m", "spring stiffness k of each element", many=True),
                  Parameter("fc", "N", "slip force f_c of each element", many=True))

    def __init__(self, k: ArrayLike, fc: ArrayLike) -> None:
        super().__init__()
        # copies: the caller's arrays, written later, must not change the link
        k_arr = np.array(k, dtype=float, ndmin=1)
        fc_arr = np.array(fc, dtype=float, ndmin=1)
        if k_arr.ndim != 1 or k_arr.size == 0:
            raise ValueError("k must be a non-empty list")
        if k_arr.shape != fc_arr.shape:
            raise ValueError(f"k and fc must have the same length ({k_arr.size} != "
                             f"{fc_arr.size})")
        for name, values in (("k", k_arr), ("fc", fc_arr)):  # one pass, the first bad one named
            bad = np.flatnonzero(~(np.isfinite(values) & (values > 0)))
            if bad.size:
                check_positive(f"{name}[{bad[0]}]", float(values[bad[0]]))
        self._k = k_arr  # what the compiled kernels are given (writable arrays: one version)
        self._fc = fc_arr
        self._stops: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
        self._elements: list[Jenkins] | None = None
        self.reset()

    @property
    def k(self) -> NDArray[np.float64]:
        """Spring stiffnesses ``k_i`` [N/m] (read-only)."""
        return _read_only(self._k)

    @property
    def fc(self) -> NDArray[np.float64]:
        """Slip forces ``fc_i`` [N] (read-only)."""
        return _read_only(self._fc)

    def __repr__(self) -> str:
        return f"MaxwellSlip(k={self.k.tolist()!r}, fc={self.fc.tolist()!r})"

    @property
    def initial_stiffness(self) -> float:
        """Sum of the spring stiffnesses [N/m]."""
        return float(self.k.sum())

    @property
    def slip_force(self) -> float:
        """Force when every element slips, ``sum fc_i`` [N]."""
        return float(self.fc.sum())

    def stop_parameters(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Stiffnesses and slip forces of the parallel stop operators."""
        return self.k.copy(), self.fc.copy()

    def periodic_stops(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The elements as parallel stop operators ``(k, fc)``, in the order of their slip
        displacements ``fc / k``: the order in which a motion makes them slip, in which
        the exact periodic output finds their slip onsets in one pass along the period.

        Examples
        --------
        >>> MaxwellSlip(k=[1.0, 2.0], fc=[1.0, 0.5]).periodic_stops()
        (array([2., 1.]), array([0.5, 1. ]))
        """
        if self._stops is None:  # once: a steady state asks for them at each point
            order = np.argsort(self._fc / self._k, kind="stable")
            self._stops = (self._k[order], self._fc[order])
        return self._stops[0].copy(), self._stops[1].copy()

    def describing_function(self, A: ArrayLike, omega: ArrayLike | None = None):
        """Sum of the elements' closed-form describing functions (eq. 10) [N/m].

        Parameters
        ----------
        A : array_like
            Amplitude(s) [m], >= 0.
        omega : array_like, optional
            Angular frequency [rad/s]; ignored (rate-independent), the result is broadcast against
            it.
        """
        a = check_amplitudes(A)
        with np.errstate(divide="ignore", over="ignore"):
            zeta = self.fc / (self.k * a[..., None])
        d = jenkins_describing_function(1.0, zeta) @ self.k.astype(complex)
        if omega is not None:
            d = np.broadcast_to(d, np.broadcast_shapes(d.shape, np.shape(omega))).copy()
        return complex(d) if d.ndim == 0 else d

    def hosidf_closed_form(self, A: ArrayLike, n_max: int) -> NDArray[np.complex128]:
        """Sum of the elements' closed-form higher-order describing functions [N/m].

        Parameters
        ----------
        A : array_like
            Amplitude(s) [m], >= 0.
        n_max : int
            Highest harmonic, >= 1.
        """
        return sum(Jenkins(ki, fi).hosidf_closed_form(A, n_max)  # no state: not .elements
                   for ki, fi in zip(self.k, self.fc, strict=True))

    @property
    def elements(self) -> list[Jenkins]:
        """The elements as Jenkins elements, made once when first asked for (a link of 1e6
        elements holds two arrays, not 1e6 objects) in the link's present state; from then on
        they are its state: :meth:`__call__` advances them and :meth:`reset` resets them."""
        if self._elements is None:
            elements = [Jenkins(ki, fi) for ki, fi in zip(self.k, self.fc, strict=True)]
            for el, w in zip(elements, self._wi.tolist(), strict=True):
                el.reset(w)
                if self._x is not None:
                    el(self._x)  # the last input, as the link has it
            self._elements = elements
        return self._elements

    def response(self, x: ArrayLike, w0: ArrayLike = 0.0) -> NDArray[np.float64]:
        """Total force for a sampled displacement; `w0` is the initial force per element.

        Parameters
        ----------
        x : array_like
            Displacement samples [m].
        w0 : float or array_like
            Initial force of each element [N], ``|w0_i| <= fc_i`` (a scalar applies to every
            element).
        """
        from motionhyst.hysteresis._kernels import maxwell_response

        xs = np.ascontiguousarray(x, dtype=float)
        if xs.ndim != 1:
            raise ValueError("x must be one-dimensional")
        if not np.all(np.isfinite(xs)):
            raise ValueError("x must be finite")
        w0s = np.broadcast_to(np.asarray(w0, dtype=float), self.k.shape).copy()
        if not np.all(np.abs(w0s) <= self.fc):
            raise ValueError("each initial force must satisfy |w0_i| <= fc_i")
        return maxwell_response(xs, self._k, self._fc, w0s).sum(axis=1)

    def periodic_harmonics(self, X: NDArray[np.complex128], n_harmonics: int,
                           omega: float | None = None) -> NDArray[np.complex128]:
        """Exact harmonics of the periodic output: the sum of the elements'.

        The elements share the reversal points of `X` and one convolution
        (see :mod:`motionhyst.hysteresis.periodic`).

        Parameters
        ----------
        X : ndarray of complex
            Harmonics ``X_0 .. X_M`` of the displacement over one period (``rfft / N`` scaling).
        n_harmonics : int
            Highest output harmonic ``H``.
        omega : float, optional
            Angular frequency of the period [rad/s]; ignored (rate-independent).
        """
        from motionhyst.hysteresis.periodic import stop_periodic_harmonics

        return stop_periodic_harmonics(np.asarray(X, dtype=complex), self._k, self._fc,
                                       n_harmonics)

    def __call__(self, x: float) -> float:
        """Advance every element by one displacement sample (python-control interface)."""
        if self._elements is not None:  # they hold the state
            return float(sum(el(x) for el in self._elements))
        x = float(np.squeeze(x))
        if not np.isfinite(x):
            raise ValueError("x must be finite")
        if self._x is not None:
            from motionhyst.hysteresis._kernels import maxwell_response

            self._wi = maxwell_response(np.array([self._x, x]), self._k, self._fc,
                                        self._wi)[-1]
        self._x = x
        return float(sum(self._wi.tolist()))  # in the elements' order, as they were added

    def reset(self, w: float = 0.0) -> None:
        """Reset the elements' state (the force `w` is shared in proportion to fc).

        Parameters
        ----------
        w : float
            Total force to start from [N].
        """
        self._wi = float(w) * (self.fc / np.sum(self.fc))
        self._x = None
        for el, share in zip(self._elements or [], self._wi.tolist(), strict=False):
            el.reset(share)

    def time_stepping(self) -> Stepping:
        """The elements as the compiled time step advances them (:mod:`.stepping`)."""
        k, fc = self.stop_parameters()
        rows = [(STOP, (float(kj), float(fj))) for kj, fj in zip(k, fc, strict=True)]
        return Stepping.from_rows(rows, float(np.sum(fc)))

    def to_dict(self) -> dict:
        """Parameters as a JSON-ready dictionary."""
        return {"model": self.name, "k": self.k.tolist(), "fc": self.fc.tolist()}


def _read_only(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """A read-only view of `a`."""
    view = a.view()
    view.flags.writeable = False
    return view
