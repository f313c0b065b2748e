"""Identification of hysteresis from measured records.

The paper (sec. VI) leaves "identification of hysteresis models for
feedforward purposes" as future work; this package identifies the parallel
Jenkins elements ``(k_i, fc_i)`` of a :class:`~motionhyst.hysteresis.MaxwellSlip`
model (paper eq. 3 per element) from

(a) force-displacement records ``(x, w)`` (:func:`identify_maxwell_slip`), and
(b) closed-loop records ``(y1, u)`` of a two-mass stage, where the link force
    is ``w = u - P1^-1 y1`` (paper eq. 1, :func:`infer_link_force`,
    :func:`identify_closed_loop`).

Method
------
With slip displacements ``d_i = fc_i / k_i`` fixed, the Maxwell-slip force is
linear in the stiffnesses: ``w = sum_i k_i s(x; d_i) + c`` with ``s(x; d)`` the
unit-stiffness stop operator of threshold ``d`` and ``c`` a force offset.

1. Regressor: unit stop operators on a log-spaced grid of thresholds from
   ``1e-3 h`` to ``h`` (``h`` the half-range of ``x``), each started relaxed.
2. Non-negative least squares (:func:`scipy.optimize.nnls`) for the weights;
   the offset is removed by centring.  Adjacent non-zero weights are merged
   into one element; elements carrying less than 0.5 % of the total slip
   force are pruned.
3. Joint refinement of all ``k_i, fc_i``, the offset and (by default) each
   element's initial force ``w_i(0) = alpha_i fc_i, |alpha_i| <= 1`` with
   bounded :func:`scipy.optimize.least_squares` and the exact (almost
   everywhere) Jacobian of the stop operator.  The objective has a kink
   wherever a slip onset moves from one sample to the next, hence many local
   minima (far apart on short records); every order is therefore refined
   from several starts: the NNLS elements merged down to ``N`` (the adjacent
   pair that costs least, before any refinement) and the best ``N - 1``
   element fit plus the grid element that best explains its residual.  The
   best of these is then moved across kinks by a derivative-free scan of each
   slip displacement (stiffnesses and offset re-solved linearly) and refined
   again, while that lowers the residual sum of squares by more than the
   noise variance.
4. Model order: every ``N`` up to the number of NNLS elements is fitted as
   in 3, then more while another element still helps.  An ``N``-element fit
   depends only on the data and the fits of lower order, so it is the same
   whether ``N`` was requested (`n_elements`) or chosen.  The order is chosen
   after refinement: the default criterion (``criterion="rms"``) picks the
   smallest ``N`` whose RMS residual exceeds the best over all orders tried by
   at most 1 % of that best or 0.1 % of the force's RMS, whichever is larger;
   ``criterion="bic"`` minimises ``n log(RSS / n) + p log n`` instead (prone
   to extra elements when the residual is not white).
5. Uncertainty: ``sigma^2 (J^T J)^-1`` at the optimum with
   ``sigma^2 = RSS / (n - p)``; parameters the data cannot determine get an
   infinite standard deviation.  For white noise this matches the scatter of
   the estimates over noise realisations (the tests check it within a factor
   of two on a short record).  An element that never slips is a spring: its
   ``fc`` is only bounded below by its largest spring force (its standard
   error is then infinite or merely local).  The formula assumes white
   residuals; with coloured noise or model error (closed-loop records, or a
   refinement stuck in a wrong local minimum) it is optimistic.

Closed-loop records
-------------------
``P1^-1`` is improper, so ``u`` and ``y1`` are passed through one proper
prefilter ``L`` (a Butterworth low-pass times ``P1``'s numerator, see
:func:`infer_link_force`), giving ``L w = L u - (L / P1) y1`` without ever
forming ``P1^-1``.  The model is fitted in that filtered domain
(``L[phi(y1)] + c`` against ``L w``), so the prefilter causes no bias.

(c) input-output records ``(force, displacement)`` of an open-loop stage, stage
    and link jointly by the simulation error
    (:func:`motionhyst.identify.input_output.identify_io`).

Modules
-------
records
    Reading and checking records.
fit
    The Maxwell-slip fit engine (force-displacement records): its compiled stop operators are
    _stop_operators, the bound before it of what any elements leave is fd_bound.
closed_loop
    The link force inferred from closed-loop records, and its fit.
input_output
    Grey-box identification of stage and link from input-output records, the
    entry point of its parts: io_records (the records), io_start (the best
    linear approximations), io_bouc_wen (the Bouc-Wen link), io_elements (the
    registry's other links), io_uncertainty (standard errors, what the records
    do not determine), residual_noise (the records' white noise, the residuals'
    correlation) and io_results (:class:`~motionhyst.identify.io_results.IOIdentification`).
result
    :class:`Identification`, the result of (a) and (b).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from motionhyst.core.exports import lazy_exports

# the names below are imported from their modules on first use (PEP 562), as the top-level
# package does: importing a submodule (the record readers the command line checks a record
# with) does not import python-control, matplotlib and scipy.optimize with the fit engines
_EXPORTS = {
    "motionhyst.core.lti": ("HoldFilter",),
    "motionhyst.identify.closed_loop": ("LinkForce", "identify_closed_loop", "infer_link_force"),
    "motionhyst.identify.fit": ("identify_maxwell_slip",),
    "motionhyst.identify.records": ("count_reversals", "load_closed_loop_csv",
                                    "load_force_displacement_csv"),
    "motionhyst.identify.result": ("Identification",),
}
__all__ = [
    "HoldFilter", "Identification", "LinkForce", "count_reversals", "identify_closed_loop",
    "identify_maxwell_slip", "infer_link_force", "load_closed_loop_csv",
    "load_force_displacement_csv",
]

if TYPE_CHECKING:
    from motionhyst.core.lti import HoldFilter
    from motionhyst.identify.closed_loop import LinkForce, identify_closed_loop, infer_link_force
    from motionhyst.identify.fit import identify_maxwell_slip
    from motionhyst.identify.records import (
        count_reversals,
        load_closed_loop_csv,
        load_force_displacement_csv,
    )
    from motionhyst.identify.result import Identification


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
