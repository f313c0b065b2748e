"""The study a user runs: a :class:`~motionhyst.study.spec.StudyDefinition` (scenario, axes,
samples, outputs) that estimates and runs itself.
"""

from __future__ import annotations

from pathlib import Path

from motionhyst.study.runner import Estimate, RunReport, estimate_study, run_study
from motionhyst.study.spec import StudyDefinition

__all__ = ["Study"]


class Study(StudyDefinition):
    """A study (:class:`~motionhyst.study.spec.StudyDefinition`) with :meth:`estimate` and
    :meth:`run`; read it with :meth:`from_file` or :meth:`from_dict`.

    Parameters
    ----------
    scenario, axes, outputs, samples, n_samples, seed, source, scenario_source
        As :class:`~motionhyst.study.spec.StudyDefinition`.
    base_dir, joint, scan
        As :class:`~motionhyst.study.spec.StudyDefinition`.

    Examples
    --------
    >>> import tomllib
    >>> from motionhyst.scenario import default_scenario_path
    >>> base = tomllib.loads(default_scenario_path().read_text())
    >>> st = Study.from_dict({"outputs": ["e1"], "axes": {"frequency_hz": [5.0, 10.0]}},
    ...                      scenario=base)
    >>> type(st).__name__, st.n_points
    ('Study', 2)
    """

    def estimate(self, workers: int = 1, store: str | Path | None = None) -> Estimate:
        """Points, time per point (measured here on a few), core-hours, disk and memory
        (:func:`motionhyst.study.estimate_study`).

        Parameters
        ----------
        workers : int
            Workers the study would run on.
        store : path, optional
            A store holding part of this study: only its missing points are counted.

        Returns
        -------
        motionhyst.study.Estimate

        Examples
        --------
        >>> import tomllib
        >>> from motionhyst.scenario import default_scenario_path
        >>> base = tomllib.loads(default_scenario_path().read_text())
        >>> st = Study.from_dict({"outputs": ["e1"], "axes": {"frequency_hz": [5.0, 10.0]}},
        ...                      scenario=base)
        >>> est = st.estimate(workers=2)
        >>> est.points, est.workers
        (2, 2)
        """
        return estimate_study(self, workers, store)

    def run(self, store: str | Path, workers: int | None = None, client=None,
            force: bool = False, progress: bool = False) -> RunReport:
        """Compute the points missing from `store` (:func:`motionhyst.study.run_study`).

        Parameters
        ----------
        store : path
            The zarr store (a folder): new, or holding this study (then resumed).
        workers : int, optional
            Local worker processes (default: every core; 0: this process).
        client : distributed.Client, optional
            Run on this dask cluster instead.
        force : bool
            Replace a store holding another study.
        progress : bool
            Points per second and the time left on stderr.

        Returns
        -------
        motionhyst.study.RunReport

        Examples
        --------
        >>> import tempfile, tomllib
        >>> from motionhyst.scenario import default_scenario_path
        >>> base = tomllib.loads(default_scenario_path().read_text())
        >>> st = Study.from_dict({"outputs": ["e1"], "axes": {"frequency_hz": [5.0, 10.0]}},
        ...                      scenario=base)
        >>> st.run(Path(tempfile.mkdtemp()) / "s.zarr", workers=0).computed
        2
        """
        return run_study(self, store, workers=workers, client=client, force=force,
                         progress=progress)
