"""The interface every hysteresis model of a dynamic link implements.

A hysteresis element maps the displacement ``x`` of the stage (the position
``y1`` of the actuated mass in the paper's Fig. 2) to the disturbance force
``w`` it exerts on the stage.  The analyses in :mod:`motionhyst` use only the
methods defined here, so every model is accepted by the quasi-linear analysis,
the periodic steady state and the time simulation.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.validation import check_amplitudes, check_positive

__all__ = ["Hysteresis", "check_amplitudes", "check_positive"]

if TYPE_CHECKING:
    from motionhyst.hysteresis.registry import Parameter
    from motionhyst.hysteresis.stepping import Stepping


class Hysteresis(ABC):
    """Base class of hysteresis elements (displacement in, force out).

    Subclasses implement :meth:`describing_function` (paper eq. 7), the
    exact sampled response :meth:`response` and :meth:`to_dict`.  Instances
    are also python-control nonlinearities without deriving from its
    ``DescribingFunctionNonlinearity`` (so that python-control is not
    imported with the models): calling one with a scalar displacement
    advances an internal state, and :func:`control.describing_function` and
    :func:`control.describing_function_response` use the closed form through
    :meth:`describing_function`, which they look up by name.

    Attributes
    ----------
    name : str
        The model's name in scenarios and the CLI (its key in
        :data:`~motionhyst.hysteresis.registry.MODELS`).
    rate_independent : bool
        True if the output depends only on the path of ``x``, not on its
        speed; the describing function then depends on amplitude only.
    parameters : tuple of Parameter
        The constructor's parameters as scenarios and ``motionhyst df`` spell them.
    defines_zeta : bool
        True if the model defines the paper's ``zeta = fc / (k A)`` (eq. 4)
        through :meth:`zeta`.

    Examples
    --------
    Every link model is a ``Hysteresis``; the analyses use only this interface:

    >>> import numpy as np
    >>> from motionhyst import Dahl, Hysteresis, Jenkins
    >>> links = [Jenkins(k=20.0, fc=0.05), Dahl(k=20.0, fc=0.05)]
    >>> all(isinstance(link, Hysteresis) for link in links)
    True
    >>> for link in links:
    ...     D = complex(np.ravel(link.describing_function(0.01))[0])   # eq. (7) at A = 10 mm
    ...     print(f"{link.name:8s} |D| = {abs(D):.3f} N/m, k = {link.initial_stiffness} N/m")
    jenkins  |D| = 6.171 N/m, k = 20.0 N/m
    dahl     |D| = 5.965 N/m, k = 20.0 N/m
    """

    name: ClassVar[str] = "hysteresis"
    rate_independent: ClassVar[bool] = True
    parameters: ClassVar[tuple[Parameter, ...]] = ()
    defines_zeta: ClassVar[bool] = False

    @property
    @abstractmethod
    def initial_stiffness(self) -> float:
        """Stiffness of the element for small motions [N/m] (upper bound of ``|D|``)."""

    @abstractmethod
    def describing_function(self, A: ArrayLike, omega: ArrayLike | None = None):
        """Describing function ``D = (b1 + j a1) / A`` (paper eq. 7) [N/m].

        Parameters
        ----------
        A : array_like
            Amplitude(s) of the input ``x = A sin(omega t)`` [m].
        omega : array_like, optional
            Angular frequency [rad/s]; ignored by rate-independent elements.

        Returns
        -------
        complex or ndarray of complex
            Same shape as `A`; phase relative to ``sin(omega t)``, positive
            phase is lead (dissipation).
        """

    @abstractmethod
    def response(self, x: ArrayLike, w0: float = 0.0) -> NDArray[np.float64]:
        """Force ``w`` for a sampled displacement ``x`` starting from force `w0`.

        The displacement is taken as monotone between samples.

        Parameters
        ----------
        x : array_like
            Displacement samples [m].
        w0 : float
            Force at the first sample [N].

        Returns
        -------
        ndarray
            Force at each sample [N].
        """

    @abstractmethod
    def to_dict(self) -> dict:
        """Parameters as a JSON-ready dictionary, with key ``model``."""

    def sine_loop(self, A: float, omega: float | None = None, n_samples: int | None = None
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """One closed period of the periodic response to ``x = A sin(omega t)``.

        Parameters
        ----------
        A : float
            Amplitude [m], > 0.
        omega : float, optional
            Angular frequency [rad/s], for rate-dependent elements.
        n_samples : int, optional
            Samples per period (default 2000 here; models with an exact periodic
            path choose their own).

        Returns
        -------
        x, w : ndarray
            Displacement [m] and force [N]; the first sample repeated at the end.
        """
        n = 2000 if n_samples is None else int(n_samples)
        theta = np.linspace(0.0, 2.0 * np.pi, n + 1)
        x = A * np.sin(np.concatenate([theta, 2.0 * np.pi + theta[1:]]))
        w = self.response(x)[n:]
        return x[n:], w

    def zeta(self, A: ArrayLike):
        """The paper's ``zeta = fc / (k A)`` (eq. 4), for models with ``defines_zeta``.

        Parameters
        ----------
        A : array_like
            Amplitude(s) [m], > 0.

        Raises
        ------
        ValueError
            For a model that does not define it.
        """
        raise ValueError(f"zeta (eq. 4) is not defined for the {self.name} model")

    #: Number of states of :meth:`state_equation` (0: the model has no smooth state equation).
    n_states: ClassVar[int] = 0

    @property
    def bristle_damping(self) -> float:
        """The damping [N s/m] of the model's force while it sticks beyond its damping at every
        amplitude: LuGre's ``sigma1``; 0 for a model without one.

        Examples
        --------
        >>> from motionhyst.hysteresis import Jenkins
        >>> Jenkins(k=20.0, fc=0.05).bristle_damping
        0.0
        """
        return 0.0

    @property
    def viscous_damping(self) -> float:
        """The part of the model's force linear in its velocity at every amplitude [N s/m]:
        LuGre's ``sigma2``, the mean of an asymmetric Coulomb link's ``c_pos`` and ``c_neg``;
        0 for a model without one.

        Examples
        --------
        >>> from motionhyst.hysteresis import Jenkins
        >>> Jenkins(k=20.0, fc=0.05).viscous_damping
        0.0
        """
        return 0.0

    def state_equation(self, z: ArrayLike, v: float):
        """The model as a smooth state equation ``z' = f(z, v)``, ``w = h(z, v)`` with its
        derivatives (see :meth:`motionhyst.hysteresis.LuGre.state_equation`).

        Parameters
        ----------
        z : array_like
            The model's states.
        v : float
            The velocity of its displacement [m/s].

        Raises
        ------
        ValueError
            For a model without one (:attr:`n_states` = 0): a rate-independent element
            switches between sticking and slipping.
        """
        raise ValueError(f"the {self.name} model has no smooth state equation")

    def rates(self, z: ArrayLike, v: float) -> tuple[ArrayLike, float]:
        """``z'`` and ``w`` of :meth:`state_equation` without its derivatives: what a run in
        time evaluates at every step (a model may give them cheaper).

        Parameters
        ----------
        z, v
            As :meth:`state_equation`.

        Returns
        -------
        zdot, w
            ``z'`` and the force [N].

        Raises
        ------
        ValueError
            For a model without a smooth state equation.

        Examples
        --------
        >>> from motionhyst.hysteresis import Dahl
        >>> zdot, w = Dahl(k=20.0, fc=0.05).rates([0.0], 0.01)     # at rest, moving forward
        >>> float(zdot[0]), w
        (0.2, 0.0)
        """
        zdot, w, *_ = self.state_equation(z, v)
        return zdot, w

    def time_stepping(self) -> Stepping:
        """The elements as the compiled time step advances them (:mod:`.stepping`).

        Raises
        ------
        ValueError
            For a model the compiled time step has no update for.
        """
        raise ValueError(f"time simulation does not support the {self.name!r} model "
                         f"({type(self).__name__})")

    def periodic_stops(self) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """Stiffnesses and slip forces of the parallel stop operators whose summed output
        is this element's periodic output, or None for another element.

        A link of stop operators (Jenkins, Maxwell-slip) has its periodic steady state
        computed by one compiled kernel (:func:`~motionhyst.analysis.steady.periodic_steady_state`).

        Examples
        --------
        >>> from motionhyst import Dahl, Jenkins
        >>> Jenkins(k=20.0, fc=0.05).periodic_stops()
        (array([20.]), array([0.05]))
        >>> Dahl(k=20.0, fc=0.05).periodic_stops() is None
        True
        """
        return None

    def periodic_harmonics(self, X: NDArray[np.complex128], n_harmonics: int,
                           omega: float | None = None) -> NDArray[np.complex128]:
        """Harmonics of the periodic output for a periodic input.

        Parameters
        ----------
        X : ndarray of complex
            Harmonics ``X_0 .. X_M`` of the displacement over one period,
            ``x(theta) = X_0 + 2 Re sum X_m exp(j m theta)`` (``rfft / N`` scaling).
        n_harmonics : int
            Highest output harmonic ``H``.
        omega : float, optional
            Angular frequency of the period [rad/s]; used by rate-dependent elements.

        Returns
        -------
        ndarray of complex, shape (H + 1,)
            Output harmonics in the same scaling.  This default samples the
            period finely and runs the element to its periodic state; elements
            with an exact method override it.
        """
        from motionhyst.hysteresis.periodic import sample_period

        H = int(n_harmonics)
        N = max(8 * H, 8 * (len(X) - 1), 8192)
        x = sample_period(X, N)
        xs = np.concatenate([x, x, x, x[:1]])
        w = self.response(xs)[2 * N: 3 * N]
        return (np.fft.rfft(w) / N)[: H + 1]

    def hosidf(self, A: ArrayLike, n_max: int, omega: float | None = None
               ) -> NDArray[np.complex128]:
        """Higher-order sinusoidal-input describing functions ``H_n(A) = Y_n / A``.

        ``Y_n`` is the complex amplitude of the output's n-th harmonic relative
        to ``sin(n omega t)`` for the input ``x = A sin(omega t)``; ``H_1`` is
        the describing function.  Computed from the exact periodic output.

        Parameters
        ----------
        A : array_like
            Amplitude(s) [m], > 0.
        n_max : int
            Highest harmonic, >= 1.
        omega : float, optional
            Angular frequency [rad/s] for rate-dependent elements.

        Returns
        -------
        ndarray of complex, shape ``A.shape + (n_max,)``
            ``H_1 .. H_n_max`` [N/m].
        """
        a = check_amplitudes(A)
        n_max = int(n_max)
        if n_max < 1:
            raise ValueError("n_max must be >= 1")
        out = np.empty((*a.shape, n_max), dtype=complex)
        for idx, amp in np.ndenumerate(a):
            if amp == 0:
                out[idx] = 0.0
                out[(*idx, 0)] = self.initial_stiffness
                continue
            W = self.periodic_harmonics(np.array([0.0, amp / 2j]), n_max, omega)
            h = 2j * W[1:] / amp
            h[np.abs(h) <= 1e-13 * np.max(np.abs(h))] = 0.0  # round-off, e.g. even harmonics
            out[idx] = h
        return out

    def reset(self, w: float = 0.0) -> None:
        """Reset the state used by :meth:`__call__` (force `w`, last input unknown).

        Parameters
        ----------
        w : float
            Force to start from [N].
        """
        self._w = float(w)
        self._x = None

    def __call__(self, x: float) -> float:
        """Advance the element by one displacement sample (python-control interface)."""
        x = float(np.squeeze(x))
        if getattr(self, "_x", None) is None:
            self._w = getattr(self, "_w", 0.0)
            self._x = x
            return self._w
        out = self.response(np.array([self._x, x]), w0=self._w)
        self._w = float(out[-1])
        self._x = x
        return self._w

    def _isstatic(self) -> bool:
        """False: calls advance a state (python-control's test for static nonlinearities)."""
        return False
