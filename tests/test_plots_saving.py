"""figure_writer: every figure in every format, drawn by worker processes or in-process."""

from __future__ import annotations

import multiprocessing
import subprocess
import sys
import textwrap
import time

import matplotlib.image
import numpy as np
import pytest

from motionhyst.hysteresis import Jenkins
from motionhyst.present import plots
from motionhyst.present.figure_writer import FigureWriter, _lay_out_once, save_figures

EL = Jenkins(k=20.0, fc=0.05)
MAKERS = {
    "fig5": lambda: plots.fig5_loops(EL),
    "fig6": lambda: plots.fig6_modes(EL),
    "fig8": lambda: plots.fig8_describing_function(EL),
}


@pytest.mark.parametrize("workers", [1, 2, 3])
def test_every_figure_in_every_format(tmp_path, workers):
    done = []
    names = save_figures(MAKERS, tmp_path, ("png", "pdf", "svg"), done=done.append,
                               workers=workers)
    assert names == list(MAKERS)  # in the makers' order, whatever order they finished in
    assert sorted(done) == sorted(MAKERS)
    files = sorted(p.name for p in tmp_path.iterdir())
    assert files == sorted(f"{n}.{ext}" for n in MAKERS for ext in ("png", "pdf", "svg"))
    for p in tmp_path.iterdir():
        head = p.read_bytes()[:8]
        assert head.startswith({".png": b"\x89PNG", ".pdf": b"%PDF", ".svg": b"<?xml"}[p.suffix])


def test_parallel_and_serial_draw_the_same_figure(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    save_figures(MAKERS, tmp_path / "a", ("svg",), workers=1)
    save_figures(MAKERS, tmp_path / "b", ("svg",), workers=2)
    for name in MAKERS:
        a = (tmp_path / "a" / f"{name}.svg").read_text()
        b = (tmp_path / "b" / f"{name}.svg").read_text()
        # identical drawings; only the ids matplotlib derives from object addresses may differ
        assert a.count("<path") == b.count("<path") and a.count("<text") == b.count("<text")
        assert len(a) == pytest.approx(len(b), rel=1e-3)


@pytest.mark.parametrize("workers", [1, 2])
def test_an_error_in_a_figure_reaches_the_caller(tmp_path, workers):
    def broken():
        raise ValueError("no data for fig9")

    with pytest.raises(ValueError, match="no data for fig9"):
        save_figures({**MAKERS, "fig9": broken}, tmp_path, ("png",), workers=workers)


@pytest.mark.parametrize("make", [lambda: plots.fig8_describing_function(EL, zeta_op=0.25),
                                  lambda: plots.fig7_time(EL, 0.01)])
def test_the_layout_solved_once_is_the_one_savefig_solves(tmp_path, make):
    # savefig lays a figure out for its first file (then kept for the others, as the report
    # always did); _lay_out_once solves it once beforehand: the same axes, pixels and PDF
    plain, once = make(), make()
    plain.savefig(tmp_path / "plain.png")
    plain.set_layout_engine("none")
    plain.savefig(tmp_path / "plain.pdf", metadata={"CreationDate": None})
    _lay_out_once(once)
    assert once.get_layout_engine() is None
    assert [ax.get_position().bounds for ax in once.axes] == \
        [ax.get_position().bounds for ax in plain.axes]
    once.savefig(tmp_path / "once.png")
    once.savefig(tmp_path / "once.pdf", metadata={"CreationDate": None})
    a = matplotlib.image.imread(tmp_path / "plain.png")
    b = matplotlib.image.imread(tmp_path / "once.png")
    assert a.shape == b.shape and np.array_equal(a, b)
    assert (tmp_path / "plain.pdf").read_bytes() == (tmp_path / "once.pdf").read_bytes()


@pytest.mark.parametrize("parallel", [False, True])
def test_writer_draws_each_batch_while_the_caller_goes_on(tmp_path, parallel):
    done = []
    with FigureWriter(tmp_path, ("png", "pdf"), done=done.append, parallel=parallel) as writer:
        writer.submit({"fig8": MAKERS["fig8"]})
        # data made after the first batch was submitted reach the workers forked after it
        el2 = Jenkins(k=40.0, fc=0.05)
        writer.submit({"fig5": lambda: plots.fig5_loops(el2), "fig6": MAKERS["fig6"]})
        assert writer.wait() == ["fig8", "fig5", "fig6"]
    assert sorted(done) == ["fig5", "fig6", "fig8"]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        f"{n}.{ext}" for n in ("fig5", "fig6", "fig8") for ext in ("png", "pdf"))
    assert multiprocessing.active_children() == []


def test_writer_stops_its_workers_when_the_caller_fails(tmp_path):
    def slow():
        time.sleep(60)
        return plots.fig6_modes(EL)

    t0 = time.monotonic()
    with pytest.raises(KeyError, match="no such data"), \
            FigureWriter(tmp_path, ("png",), parallel=True) as writer:
        writer.submit({"fig6": slow})
        raise KeyError("no such data")  # the caller's computation fails meanwhile
    assert time.monotonic() - t0 < 30  # the worker was stopped, not waited for
    assert multiprocessing.active_children() == []
    assert list(tmp_path.iterdir()) == []


def test_writer_reports_the_first_error_with_the_workers_traceback(tmp_path):
    def broken():
        raise ValueError("no data for fig9")

    with FigureWriter(tmp_path, ("png",), parallel=True) as writer:
        writer.submit({"fig5": MAKERS["fig5"]})
        writer.submit({"fig9": broken})
        with pytest.raises(ValueError, match="no data for fig9") as err:
            writer.wait()
    assert "in broken" in str(err.value.__cause__)  # where it failed, in the worker
    assert multiprocessing.active_children() == []


def test_figures_module_still_offers_the_writer():
    from motionhyst.present import figures

    assert figures.FigureWriter is FigureWriter and figures.save_figures is save_figures


def test_a_caller_without_matplotlib_leaves_loading_it_to_the_worker(tmp_path):
    # the caller forks its first worker before importing matplotlib: the worker loads it (and
    # the backends) and draws; the caller never imports it
    script = textwrap.dedent(f"""
        import sys
        from motionhyst.present.figure_writer import FigureWriter
        from motionhyst.hysteresis import Jenkins

        def fig5():
            from motionhyst.present.plots import fig5_loops
            return fig5_loops(Jenkins(k=20.0, fc=0.05))

        with FigureWriter({str(tmp_path)!r}, ("png", "pdf"), parallel=True) as writer:
            writer.submit({{"fig5": fig5}})
            assert writer.wait() == ["fig5"]
        print("matplotlib" in sys.modules)
    """)
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "False"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fig5.pdf", "fig5.png"]
    assert matplotlib.image.imread(tmp_path / "fig5.png").shape[0] > 100
