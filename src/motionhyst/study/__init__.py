"""Studies: a scenario swept over axes of its keys and the reference, with Monte-Carlo samples,
computed on every local core or a dask cluster into a resumable zarr store.

:class:`Study` reads a study file (:mod:`motionhyst.study.spec`) and runs itself;
:func:`run_study` computes it (:mod:`motionhyst.study.runner`, engines in
:mod:`motionhyst.study.engine`),
:func:`open_results` reads the store as an :class:`xarray.Dataset` and :func:`summarize` gives
the worst case per axis and the Monte-Carlo band.  Outputs are named functions of one point
(:data:`OUTPUTS`, :func:`register_output`).
"""

from motionhyst.study.outputs import OUTPUTS, Output, Point, register_output
from motionhyst.study.runner import Estimate, RunReport, estimate_study, run_study
from motionhyst.study.spec import StudyDefinition, StudyError
from motionhyst.study.store import StudyStore, open_results
from motionhyst.study.study import Study
from motionhyst.study.summary import StudySummary, summarize

__all__ = ["OUTPUTS", "Estimate", "Output", "Point", "RunReport", "Study", "StudyDefinition",
           "StudyError", "StudyStore", "StudySummary", "estimate_study", "open_results",
           "register_output", "run_study", "summarize"]
