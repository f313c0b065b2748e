"""Drawing and saving figures in forked worker processes while the caller computes.

Laying out and rendering a figure is pure Python in matplotlib and takes far
longer than computing its data: :class:`FigureWriter` hands each batch of
figures to a forked worker, :func:`save_figures` shares a set of figures out
among the cores.  This module imports matplotlib only when a figure is
drawn, so a caller can fork its first worker before it has loaded
matplotlib itself (the worker loads it while the caller goes on).
"""

from __future__ import annotations

import gc
import io
import multiprocessing
import os
import signal
import sys
import traceback
from collections.abc import Callable, Sequence
from multiprocessing.connection import Connection
from multiprocessing.connection import wait as wait_connections
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["FigureMaker", "FigureWriter", "save_figures"]

FigureMaker = Callable[[], "Figure"]
"""A function that draws a figure and returns it."""


def _draw_and_save(name: str, make: FigureMaker, folder: Path, formats: Sequence[str]) -> None:
    """Draw figure `name` with `make` and save it as ``folder/<name>.<format>`` in every format."""
    fig = make()
    _lay_out_once(fig)
    for fmt in formats:
        fig.savefig(folder / f"{name}.{fmt}")


def _lay_out_once(fig: Figure) -> None:
    """Solve `fig`'s layout now, as the first ``savefig`` would, and keep it for every file.

    With a layout engine, every ``savefig`` draws the figure once without
    rendering to solve the layout and then once more to render it.  The
    layout found at the figure's own dpi (what ``savefig`` solves it at) holds
    for every format (same size in inches, same text), so it is solved here
    once, on an Agg canvas, and the engine is removed: each file is then drawn
    once, the same files in a quarter less time.
    """
    engine = fig.get_layout_engine()
    if engine is None:
        return
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    if not isinstance(fig.canvas, FigureCanvasAgg):
        FigureCanvasAgg(fig)
    engine.execute(fig)
    fig.set_layout_engine(None)


def _usable_cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - platforms without affinity
        return os.cpu_count() or 1


def _can_fork() -> bool:
    """Whether figures are drawn by forked workers: ``fork`` exists and more than one core."""
    return "fork" in multiprocessing.get_all_start_methods() and _usable_cores() > 1


_warm_formats: set[str] = set()
"""The formats this process has drawn a figure in (inherited by forked workers)."""


def _warm_up(formats: Sequence[str]) -> None:
    """Load what drawing any figure loads at its first use, once, before forking workers.

    The formats' backends, the font and the math-text parser (tick labels of
    log axes): each worker forked afterwards inherits them instead of loading
    its own.
    """
    todo = [fmt for fmt in formats if fmt not in _warm_formats]
    if not todo:
        return
    from matplotlib.backend_bases import get_registered_canvas_class
    from matplotlib.figure import Figure

    import motionhyst.core.plotting  # noqa: F401  (matplotlib as the figures have it set up)

    for fmt in todo:
        get_registered_canvas_class(fmt)
    fig = Figure(layout="constrained")
    ax = fig.subplots()
    ax.set_title("warm-up")
    ax.loglog([1.0, 100.0], [1.0, 10.0])
    fig.savefig(io.BytesIO(), format="png")
    _warm_formats.update(todo)


_WORKER_SIGNALS = frozenset({signal.SIGINT, signal.SIGTERM})
"""The signals a worker takes as its own from its start (see :func:`_draw_batch`)."""


def _block(signals: frozenset[signal.Signals]) -> set[signal.Signals]:
    """Block `signals` in this thread; the mask there was before, to set back."""
    return signal.pthread_sigmask(signal.SIG_BLOCK, signals)


class _WorkerTraceback(Exception):
    """The traceback of an error in a figure worker (the cause of the error re-raised)."""


def _draw_batch(makers: dict[str, FigureMaker], folder: Path, formats: Sequence[str],
                conn) -> None:
    """A worker's job: draw `makers` in order, sending each name (or the error) on `conn`.

    A kernel compiled here is not announced on stderr: the caller announces its own.
    """
    from motionhyst.core.compiled import quiet_compilation

    # the caller ends its workers (FigureWriter.close, with SIGTERM), whatever handlers it has:
    # a worker dies at SIGTERM and leaves Ctrl-C to the caller.  Both signals are blocked
    # from before the fork (FigureWriter.submit) until the worker's own dispositions are
    # set: one that comes sooner waits and is then taken as set here, never by a handler
    # of the caller's, which would raise in the worker before multiprocessing's guard and
    # send this copy of the caller on through the caller's own code
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _WORKER_SIGNALS)
    quiet_compilation()
    try:
        for name, make in makers.items():
            _draw_and_save(name, make, folder, formats)
            conn.send(("done", name))
    except BaseException as exc:  # every error, interruptions included, goes to the caller
        tb = traceback.format_exc()
        try:
            conn.send(("error", exc, tb))
        except Exception:  # an error that does not pickle: its text
            conn.send(("error", RuntimeError(f"{type(exc).__name__}: {exc}"), tb))
    finally:
        conn.close()


class FigureWriter:
    """Draws and saves figures in forked worker processes while the caller goes on computing.

    Laying out and rendering a figure (constrained layout, tick labels of log
    axes, the PNG and PDF backends) is pure Python in matplotlib and takes far
    longer than computing its data.  Each :meth:`submit` forks a worker that
    draws its figures one after the other and saves each as
    ``folder/<name>.<format>`` in every format, while the caller computes the
    data of the next ones; the worker inherits the figure makers and their
    data through ``fork`` (nothing is pickled but the names and errors sent
    back).  Without ``fork`` (Windows) or with one usable core, :meth:`submit`
    draws the figures in this process before it returns.

    Used as a context manager: leaving it, on success or on an error, stops
    the workers still drawing (their files are then incomplete: write into a
    scratch folder and move the files once :meth:`wait` has returned).

    Parameters
    ----------
    folder : str or Path
        Existing folder the files are written into.
    formats : sequence of str
        File formats (extensions), each written for every figure.
    done : callable, optional
        Called with each figure's name once its files are written (progress;
        for the workers' figures, while :meth:`wait` waits).
    parallel : bool, optional
        Draw in forked workers; by default when ``fork`` exists and more than
        one core is usable.

    Notes
    -----
    Matplotlib's backends, fonts and math-text parser take a few tenths of a
    second to load at their first use.  If the caller has imported
    matplotlib, :meth:`submit` loads them once in the caller and every worker
    inherits them; if not (a caller forking its first worker straight away),
    the worker loads what its figures need, and the caller goes on at once.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from motionhyst.present.figure_writer import FigureWriter
    >>> from motionhyst.hysteresis import Jenkins
    >>> from motionhyst.present.plots import fig5_loops, fig8_describing_function
    >>> el = Jenkins(k=20.0, fc=0.05)
    >>> folder = Path(tempfile.mkdtemp())
    >>> with FigureWriter(folder, ("png", "pdf")) as figures:
    ...     figures.submit({"fig5": lambda: fig5_loops(el)})  # drawn while fig8's data is made
    ...     figures.submit({"fig8": lambda: fig8_describing_function(el)})
    ...     figures.wait()
    ['fig5', 'fig8']
    >>> sorted(p.name for p in folder.iterdir())
    ['fig5.pdf', 'fig5.png', 'fig8.pdf', 'fig8.png']
    """

    def __init__(self, folder: str | Path, formats: Sequence[str] = ("png", "pdf"),
                 done: Callable[[str], None] | None = None,
                 parallel: bool | None = None) -> None:
        self.folder = Path(folder)
        self.formats = tuple(formats)
        self.done = done
        self.parallel = _can_fork() if parallel is None else bool(parallel)
        self._names: list[str] = []
        self._workers: list[tuple[multiprocessing.process.BaseProcess, Connection]] = []

    def __enter__(self) -> FigureWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def submit(self, makers: dict[str, FigureMaker]) -> None:
        """Draw and save `makers` (name -> function returning the figure) in a new worker.

        Parameters
        ----------
        makers : dict
            File name -> function that returns the figure.
        """
        self._names += list(makers)
        if not self.parallel:
            for name, make in makers.items():
                _draw_and_save(name, make, self.folder, self.formats)
                self._done(name)
            return
        if "matplotlib" in sys.modules:  # once, here, rather than in every worker
            _warm_up(self.formats)
        ctx = multiprocessing.get_context("fork")
        receive, send = ctx.Pipe(duplex=False)
        worker = ctx.Process(target=_draw_batch, daemon=True,
                             args=(dict(makers), self.folder, self.formats, send))
        # the worker's garbage collections leave alone the objects it inherits (all of this
        # process's): without, each goes through them all and copies their memory pages, a
        # quarter of a figure's drawing time
        gc.freeze()
        blocked = _block(_WORKER_SIGNALS)  # unblocked in the worker by _draw_batch
        try:
            worker.start()
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
            gc.unfreeze()
        send.close()
        self._workers.append((worker, receive))

    def wait(self) -> list[str]:
        """Wait until every figure submitted is saved; their names, in the order submitted.

        Raises the first error a worker met (its traceback as the cause), after
        stopping the other workers.
        """
        try:
            while self._workers:
                for conn in wait_connections([c for _, c in self._workers]):
                    try:
                        message = conn.recv()
                    except EOFError:  # the worker has finished
                        worker = self._finished(conn)
                        if worker.exitcode != 0:
                            raise RuntimeError(f"a figure worker ended with exit code "
                                               f"{worker.exitcode}") from None
                        continue
                    if message[0] == "done":
                        self._done(message[1])
                    else:
                        raise message[1] from _WorkerTraceback(message[2])
        finally:
            self.close()
        return list(self._names)

    def close(self) -> None:
        """Stop the workers still drawing (nothing to do once :meth:`wait` has returned)."""
        while self._workers:
            worker, conn = self._workers.pop()
            if worker.is_alive():
                worker.terminate()
            worker.join()
            conn.close()

    def _finished(self, conn: Connection) -> multiprocessing.process.BaseProcess:
        i = next(i for i, (_, c) in enumerate(self._workers) if c is conn)
        worker, _ = self._workers.pop(i)
        worker.join()
        conn.close()
        return worker

    def _done(self, name: str) -> None:
        if self.done is not None:
            self.done(name)


def save_figures(makers: dict[str, FigureMaker], folder: str | Path,
                 formats: Sequence[str] = ("png", "pdf"),
                 done: Callable[[str], None] | None = None,
                 workers: int | None = None) -> list[str]:
    """Draw figures and save each as ``folder/<name>.<format>``, several at a time.

    The figures are shared out among `workers` forked worker processes (one
    per usable core by default, at most one per figure), each drawing its
    share one after the other through a :class:`FigureWriter`; without
    ``fork`` (Windows, or one core) they are drawn in this process, one after
    the other.

    Parameters
    ----------
    makers : dict
        Figure name -> function returning the :class:`~matplotlib.figure.Figure`.
    folder : str or Path
        Existing folder the files are written into.
    formats : sequence of str
        File formats (extensions), each written for every figure.
    done : callable, optional
        Called with each figure's name once its files are written (progress).
    workers : int, optional
        Processes to use; by default the usable cores, at most one per figure.

    Returns
    -------
    list of str
        The names, in the order of `makers`.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from motionhyst.hysteresis import Jenkins
    >>> from motionhyst.present.figure_writer import save_figures
    >>> from motionhyst.present.plots import fig5_loops, fig8_describing_function
    >>> el = Jenkins(k=20.0, fc=0.05)
    >>> folder = Path(tempfile.mkdtemp())
    >>> save_figures({"fig5": lambda: fig5_loops(el), "fig8": lambda: fig8_describing_function(el)},
    ...              folder)
    ['fig5', 'fig8']
    >>> sorted(p.name for p in folder.iterdir())
    ['fig5.pdf', 'fig5.png', 'fig8.pdf', 'fig8.png']
    """
    items = list(makers.items())
    if workers is None:
        n = min(_usable_cores(), len(items)) if _can_fork() else 1
    else:
        n = max(1, min(int(workers), len(items)))
    with FigureWriter(folder, formats, done=done, parallel=n > 1) as writer:
        for i in range(n):  # figure i to worker i mod n
            writer.submit(dict(items[i::n]))
        writer.wait()
    return [name for name, _ in items]
