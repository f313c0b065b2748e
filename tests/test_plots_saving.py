"""figures.save_figures: every figure in every format, drawn by worker processes or in-process."""

from __future__ import annotations

import matplotlib.image
import numpy as np
import pytest

from motionhyst import plots
from motionhyst.figures import _lay_out_once, save_figures
from motionhyst.hysteresis import Jenkins

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
