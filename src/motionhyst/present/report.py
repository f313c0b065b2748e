"""``motionhyst reproduce``: the paper's figures and numbers for a scenario, as a report.

Writes Figs. 5-11 (PNG and PDF), ``summary.json`` (the analyze and simulate
results) and ``report.md`` into an output folder, through
:class:`motionhyst.io.outputs.OutputFolder`: everything is computed first, then
each file is staged in the folder and all are moved into place together and
listed in the folder's manifest; the user's own files in the folder are never
touched.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from tqdm import tqdm

from motionhyst.core.jsonio import dumps
from motionhyst.hysteresis.periodic import TWO_PI
from motionhyst.io.leftovers import scratch_folder
from motionhyst.io.outputs import OutputFolder
from motionhyst.present.figure_writer import FigureWriter
from motionhyst.scenario import Scenario

# the report is run by `motionhyst reproduce` (motionhyst.cli.reproduce): no library API
__all__ = []

if TYPE_CHECKING:
    from motionhyst.analysis.digital import DigitalComparison
    from motionhyst.analysis.quasilinear import QuasiLinearAnalysis
    from motionhyst.analysis.steady import SteadyState
    from motionhyst.hysteresis import Hysteresis
    from motionhyst.plants.frf_fit import FrfFit

# Numbers the paper states for Table I (section V and Fig. 8).
PAPER_VALUES = {
    "zeta": ("0.25", "zeta"),
    "df_abs_over_k": ("~0.3", "\\|D\\| / k"),
    "df_phase_deg": ("~50 deg", "angle D"),
    "f_star_hz": ("0.15 Hz", "f* (eq. 13)"),
    "mismatch_crossover_hz": ("7.6 Hz", "crossover (eq. 21)"),
    "bandwidth_hz": ("120 Hz", "bandwidth (crossover: first \\|C P2\\| = 1)"),
}

# Loop margins of C P2 (not stated in the paper): key, label, unit.
MARGIN_ROWS = (
    ("gain_margin_db", "gain margin", " dB", "gain_margin_hz"),
    ("phase_margin_deg", "phase margin", " deg", "phase_margin_hz"),
    ("modulus_margin", "modulus margin 1 / max \\|S\\|", "", "modulus_margin_hz"),
)

#: The exact crossover and what it is (it is not a quantity of the paper).
EXACT_CROSSOVER_LABEL = "exact crossover, \\|E - 1\\| = 1 on eq. (18)"
EXACT_CROSSOVER_NOTE = ("Exact crossover: where \\|E - 1\\| = 1 on eq. (18), i.e. the error "
                        "that the link adds equals the error without it. It is not a quantity of "
                        "the paper: eq. (21) estimates the same frequency from the asymptote of "
                        "eq. (20). The bandwidth is the crossover frequency of the open loop, the "
                        "lowest frequency where \\|C P2\\| falls through 1; the margins are "
                        "those of C P2 without the link (as control.stability_margins defines "
                        "them).")

FIGURE_NOTES = {
    "fig5": "Displacement-force loops of the Jenkins element for sinusoids at several zeta: "
            "a spring while it sticks, flat at +-fc while it slips; zeta >= 1 never slips.",
    "fig6": "The two nonlinear modes: for zeta <= 0.5 the element starts to slip where x w <= 0, "
            "for 0.5 < zeta < 1 where x w > 0 (dots).",
    "fig7": "Upper panel: the input x(t) = A sin(2 pi f t) with its amplitude A. Lower panel: "
            "the element's force w(t) over one period (eq. 5, black), the slip intervals "
            "|w| = fc shaded, the switching instants tau_i between sticking and slipping "
            "(dash-dotted, from eq. 6) and the first harmonic that the describing function "
            "keeps (eq. 7, dashed red).",
    "fig8": "Magnitude and phase of the describing function against zeta (eq. 10): a small "
            "lead-dominated force for small zeta, the spring k for zeta >= 1; shaded the modes "
            "of operation (2: zeta <= 0.5, 3: 0.5 < zeta < 1, linear: zeta >= 1); the orange "
            "point marks the operating point of section V (zeta = 0.25 for Table I: "
            "|D| ~ 0.3 k, angle ~50 deg).",
    "fig5-other": "Displacement-force loops of the scenario's link for sinusoids at several "
                  "zeta = fc / (k A) (total slip force over initial stiffness times amplitude).",
    "fig8-other": "Magnitude and phase of the scenario's link's describing function against "
                  "zeta = fc / (k A): from the initial stiffness for small amplitudes to a "
                  "lead-dominated force for large ones.",
    "fig9": "The quasi-linear plant P^phi = P2 / (1 + D P1) (eq. 12) for zeta from 0.01 to 1 "
            "(colours, with the amplitude A = fc / (k zeta) each stands for) and the floating "
            "mass P2 without link (black dashed); the dotted red line is f* (eq. 13), above "
            "which P^phi is P2. Left: the figure as the paper states it (Table I stage, "
            "Jenkins kJ = 1e4 N/m, fc = 100 N, f* = 3.4 Hz); right: this scenario's stage and "
            "link.",
    "fig10": "Black: |E| of eq. (18), the quasi-linear error with the link over the error "
             "without it. Dashed red: its low-frequency asymptote |E~| of eq. (20). Circles: "
             "the same ratio from the exact periodic steady state of the nonlinear loop (first "
             "harmonics). Grey: |E| = 1, no mismatch (eq. 22). Dotted green: eq. (21), where "
             "|E~| = 1. Dash-dotted green: where |E - 1| = 1 on eq. (18), i.e. the error the "
             "link adds equals the error without it; this exact counterpart of eq. (21) is not "
             "a quantity of the paper.",
    "plant_fit": "Measured P1 (collocated) and P2 (non-collocated) as circles and the fitted "
                 "rigid body plus modes as lines, drawn densely so that a resonance between "
                 "measured lines shows; dotted: the fitted modes' frequencies.",
    "fig11": "Steady-state error over a period with and without the dynamic link, the "
             "describing-function estimate of its first harmonic, and the sum of harmonics "
             "1-7 predicted by the higher-order describing functions.",
}


def _fmt(x) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    return f"{x:.4g}"


def _computed(analysis: QuasiLinearAnalysis, key: str) -> float | None:
    """A number of :data:`PAPER_VALUES` from the analysis (the describing function's as
    ``|D| / k`` and its angle in degrees)."""
    if key == "df_abs_over_k":
        return abs(analysis.D) / analysis.k_link
    if key == "df_phase_deg":
        return float(np.degrees(np.angle(analysis.D)))
    return getattr(analysis, key)


def _report_text(sc: Scenario, link: Hysteresis, analysis: QuasiLinearAnalysis,
                 states: list[SteadyState], E_df: Iterable[complex], fit: FrfFit | None,
                 figures: list[str], is_paper: bool, notes: list[str],
                 digital: DigitalComparison | None = None) -> str:
    """``report.md`` from the results: the analysis, the steady states with the describing
    function's mismatch at their frequencies, the digital loop beside the continuous one,
    the plant's fit, the figures drawn."""
    jenkins = link.name == "jenkins"
    lines = [f"# motionhyst report: {sc.source}", ""]
    lines += ["## Paper vs computed" if is_paper else "## Key numbers", ""]
    head = "| quantity | paper | computed |" if is_paper else "| quantity | computed |"
    lines += [head, "|---|---|---|" if is_paper else "|---|---|"]
    units = {"f_star_hz": " Hz", "mismatch_crossover_hz": " Hz", "bandwidth_hz": " Hz",
             "df_phase_deg": " deg"}
    df_f = analysis.df_frequency_hz
    at = "" if df_f is None else f" (at {_fmt(df_f)} Hz)"
    for key, (paper, label) in PAPER_VALUES.items():
        val = _fmt(_computed(analysis, key))
        val += "" if val == "n/a" else units.get(key, "") + (at if key.startswith("df_") else "")
        lines.append(f"| {label} | {paper} | {val} |" if is_paper else f"| {label} | {val} |")
    exact = _fmt(analysis.mismatch_crossover_exact_hz)
    exact += "" if exact == "n/a" else " Hz"
    lines.append(f"| {EXACT_CROSSOVER_LABEL} | - | {exact} |" if is_paper
                 else f"| {EXACT_CROSSOVER_LABEL} | {exact} |")
    margins = analysis.margins
    if margins is not None:
        for key, label, unit, fkey in MARGIN_ROWS:
            val = f"{_fmt(getattr(margins, key))}{unit} at {_fmt(getattr(margins, fkey))} Hz"
            lines.append(f"| {label} | - | {val} |" if is_paper else f"| {label} | {val} |")
    lines += ["", EXACT_CROSSOVER_NOTE]
    if margins is not None and margins.evaluated_on != "model":
        lines += ["", f"Margins and bandwidth evaluated on the {margins.evaluated_on} only."]
    if fit is not None:
        lines += ["", "## Measured plant", "",
                  "The measured plant is fitted to a rigid body plus flexible modes "
                  "(`motionhyst.plants.frf_fit`); every number and figure of this report comes "
                  "from the fitted model.", "", "```", str(fit), "```"]
    if states:
        lines += ["", "Mismatch at the reference frequencies: describing function (eq. 18) "
                  "against the exact periodic steady state of the nonlinear loop.", "",
                  "| f [Hz] | \\|E\\| eq. (18) | angle [deg] | \\|E\\| exact | angle [deg] | "
                  "\\|e1\\| [m] | \\|e3\\| [m] | peak e [m] |", "|---|---|---|---|---|---|---|---|"]
    for st, E in zip(states, E_df, strict=True):
        e3 = float(abs(st.e[3])) if st.n_harmonics >= 3 else None
        E_sim = st.mismatch  # nan where the loop without the link has no error
        lines.append(f"| {_fmt(st.frequency_hz)} | {_fmt(abs(E))} | "
                     f"{np.degrees(np.angle(E)):.2f} | {_fmt(abs(E_sim))} | "
                     f"{np.degrees(np.angle(E_sim)):.2f} | {_fmt(float(abs(st.e[1])))} | "
                     f"{_fmt(e3)} | {_fmt(st.error_peak)} |")
    if digital is not None:
        lines += ["", "## The loop as a real-time computer runs it", "",
                  f"The {'paper' if is_paper else 'scenario'}'s loop with its controller "
                  f"discretised (Tustin) at {digital.sample_rate_hz:g} Hz, the force applied "
                  f"{digital.delay_samples:g} samples after the position is sampled and held "
                  "(zero-order hold), against the continuous loop the analysis above is of; in "
                  "the last column the rigid-body feedforward reads the reference "
                  f"{digital.advance_samples:g} samples ahead (the delay and the hold's half "
                  "sample), as machines do. Exact: the periodic steady state of the hybrid "
                  "loop (n/a where the period is not a whole number of samples).", ""]
        head, rows = digital.rows()
        lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        lines += ["| " + " | ".join(c.replace("|", "\\|") for c in r) + " |" for r in rows]
    lines += ["", "## Figures", ""]
    for name in figures:
        note = FIGURE_NOTES.get(name if jenkins else f"{name}-other", FIGURE_NOTES[name])
        lines += [f"### {name}", "", note, "", f"![{name}]({name}.png)", ""]
    if notes:
        lines += ["## Notes", ""] + [f"- {n}" for n in notes] + [""]
    return "\n".join(lines)


FIGURES = ("fig5", "fig6", "fig7", "fig8", "fig9", "fig10", "fig11", "plant_fit")
"""Figures the report may hold (Figs. 6-7 only for a link with zeta = fc / (k A), plant_fit
only for a measured plant that is fitted)."""

OUTPUT_NAMES = (*(f"{f}.{ext}" for f in FIGURES for ext in ("png", "pdf")), "summary.json",
                "report.md")
"""Every file :func:`reproduce` may write into its folder (besides the manifest)."""


def _plots():
    """:mod:`motionhyst.present.plots`, imported where a figure is drawn (it imports matplotlib)."""
    from motionhyst.present import plots

    return plots


def _link_figures(el: Hysteresis, A: float, freqs: list[float]) -> dict:
    """The figures of the link alone (Figs. 5-8): they need neither the loop nor its analysis.

    Fig. 8 marks the operating point ``zeta = fc / (k A)`` of the reference
    amplitude (eq. 4), the zeta :func:`~motionhyst.analysis.quasilinear.analyze`
    reports; Figs. 6-7 only for a link with the Jenkins element's slip modes.
    """
    zeta_op = float(el.zeta(A)) if el.defines_zeta else None
    figs = {
        "fig5": lambda: _plots().fig5_loops(el, frequency_hz=freqs[0]),
        "fig6": lambda: _plots().fig6_modes(el),
        "fig7": lambda: _plots().fig7_time(el, A, freqs[0]),
        "fig8": lambda: _plots().fig8_describing_function(el, frequency_hz=freqs[0],
                                                          zeta_op=zeta_op),
    }
    if not el.defines_zeta:
        del figs["fig6"], figs["fig7"]
    return figs


def reproduce(sc: Scenario, out_dir: str | Path, quiet: bool = False,
              is_paper: bool = False, force: bool = False,
              inputs: Iterable[str | Path | None] = (),
              checked: Callable[[], None] | None = None) -> dict:
    """Write the figures, ``summary.json`` and ``report.md`` for scenario `sc` into `out_dir`.

    The folder is an :class:`~motionhyst.io.outputs.OutputFolder`: it may hold
    the user's own files, which are never touched; the report's files are
    listed in its manifest and replaced by a later run; the files are staged
    once everything has been computed and moved into place together, so a run
    that fails leaves the previous report as it was.

    Parameters
    ----------
    sc : Scenario
        The scenario.
    out_dir : str or Path
        Output folder, created if absent (``"."`` is the current folder).
    quiet : bool
        No progress bar.
    is_paper : bool
        Compare with the numbers the paper states (Table I scenario).
    force : bool
        Also replace files of the report's names that motionhyst did not write, and a
        symbolic link named `out_dir`.
    inputs : iterable of paths
        Files the command read (the scenario): never replaced.
    checked : callable, optional
        Called once the loop is built and checked, its frequencies are known good
        (:func:`~motionhyst.analysis.plausibility.check_frequency_range`,
        :func:`~motionhyst.analysis.steady.check_steady_frequencies`) and its steady states
        have answered (a loop that hunts has none: refused in one line,
        :func:`~motionhyst.analysis.hunting.steady_state_unless_hunting`); the command shows
        the warnings it held until then.

    Returns
    -------
    dict
        The summary (also written as ``summary.json``).

    Raises
    ------
    motionhyst.io.outputs.OutputError
        Before any computation, if `out_dir` is a file, or a symbolic link or holds a
        file of the report's names that motionhyst did not write and `force` is false
        (with it the link itself is replaced by the folder, never what it points to).
    """
    folder = OutputFolder(out_dir, OUTPUT_NAMES, force=force, inputs=inputs)
    A, freqs = sc.amplitude, sc.frequencies
    el = sc.hysteresis()
    show = not quiet and sys.stderr.isatty()
    notes: list[str] = []
    try:
        steps = tqdm(total=10, desc="reproduce", disable=not show, file=sys.stderr, leave=False)
        # the figures are drawn by worker processes into a scratch folder outside the user's
        # folder, each as soon as its data is computed, while the next data is computed; each
        # figure's files are staged in the output folder as soon as they are written (and all
        # are moved into place together at the end; SIGTERM cleans up)
        def stage(name: str) -> None:
            for ext in ("png", "pdf"):
                folder.write_bytes(f"{name}.{ext}", (Path(scratch) / f"{name}.{ext}").read_bytes())
            steps.update()

        with (folder, scratch_folder("motionhyst-figures") as scratch,
              FigureWriter(scratch, ("png", "pdf"), done=stage) as figures):
            # Figs. 5-8 need no loop: at once, a worker loads the link's compiled kernels (numba)
            # and matplotlib and draws them while this process imports the analysis
            # (python-control) and builds the loop; the later workers inherit both from this
            # process (python-control imports matplotlib)
            figures.submit(_link_figures(el, A, freqs))
            from motionhyst.analysis.comparison import ComparisonPoint
            from motionhyst.analysis.hunting import steady_state_unless_hunting
            from motionhyst.analysis.plausibility import check_frequency_range
            from motionhyst.analysis.quasilinear import analyze, error_harmonics_df, loop_mismatch
            from motionhyst.analysis.steady import check_steady_frequencies

            loop = sc.loop()
            check_frequency_range(loop, freqs)  # what the analyses refuse as they start
            if loop.plant.is_lti:  # raw measured lines have no steady state: none computed
                check_steady_frequencies(loop, freqs)
            analysis = analyze(loop, A, freqs)
            steps.update()
            figures.submit({"fig9": lambda: _plots().fig9_quasilinear_plant(
                loop, f_star_hz=analysis.f_star_hz)})
            fit = sc.plant_fit()
            if fit is not None:
                figures.submit({"plant_fit": fit.plot})
            # the link's kernels, loaded only now (Fig. 9 needs none for a rate-independent
            # link): the steady states need them, and the later workers inherit them
            el.sine_loop(A, None if el.rate_independent else TWO_PI * freqs[0])
            raw_data = not loop.plant.is_lti
            if raw_data:  # the steady state needs the plant at every harmonic: no exact results
                states, E_df, H_df, exact = [], [], [], []
            else:
                states = [steady_state_unless_hunting(loop, A, f) for f in freqs]
                E_df = loop_mismatch(loop, freqs, A)
                H_df = [error_harmonics_df(loop, A, f, n_max=7) for f in freqs]
                figures.submit({"fig11": lambda: _plots().fig11_errors(states, E_df, H_df)})
                steps.update()
                lo, hi = loop.plant.frequency_range_hz or (1.0, 100.0)
                f_exact = np.geomspace(max(1.0, lo), min(100.0, hi / 10.0), 13)
                if loop.sampled is not None:  # the hybrid loop's: whole samples per period
                    rate = loop.sampled.sample_rate_hz
                    f_exact = rate / np.maximum(3, np.round(rate / f_exact))
                f_exact = np.unique(np.concatenate([f_exact, freqs]))
                exact = [steady_state_unless_hunting(loop, A, f) for f in f_exact]
            # the steady states have answered (a loop that hunts is refused in one line, the
            # warnings held): the warnings are shown as the figures and the report follow
            if checked is not None:
                checked()
            digital = None
            if not raw_data and loop.sampled is None and loop.hysteresis is not None:
                from motionhyst.analysis.digital import compare_digital

                digital = compare_digital(loop, A, freqs)
            figures.submit({"fig10": lambda: _plots().fig10_mismatch(loop, analysis, exact)})
            steps.update()
            summary = {
                "scenario": sc.to_dict(),
                "analyze": analysis.to_dict(),
                "simulate": {"points": [ComparisonPoint(s, complex(e), h).to_dict()
                                        for s, e, h in zip(states, E_df, H_df, strict=True)]},
            }
            if fit is not None:
                summary["plant_fit"] = fit.to_dict()
            if digital is not None:
                summary["digital"] = digital.to_dict()
            if not el.defines_zeta:
                at = "" if el.rate_independent else f" at {freqs[0]:g} Hz"
                notes.append(f"Figs. 6-7 show the slip modes of the paper's single Jenkins "
                             f"element; the scenario's link is a {el.name} model, so they are not "
                             f"drawn. Figs. 5 and 8 show its loops and describing function{at}, "
                             f"with zeta = fc / (k A) from its total slip force and initial "
                             f"stiffness.")
            if raw_data:
                notes.append("The plant is raw measured frequency-response data (use = "
                             "\"data\"): only the measured lines are evaluated; eq. (21) and the "
                             "exact steady state (the mismatch table's exact columns, Fig. 10's "
                             "circles, Fig. 11) need a model and are not computed. Quantities "
                             "the data cannot resolve are listed below and are n/a.")
                notes += analysis.unresolved
            drawn = set(figures.wait())
            written = [name for name in FIGURES if name in drawn]
            folder.write_bytes("summary.json", dumps(summary).encode())
            folder.write_bytes("report.md", _report_text(sc, el, analysis, states, E_df, fit,
                                                         written, is_paper, notes,
                                                         digital).encode())
            steps.close()
    except BaseException:
        folder.abandon()
        raise
    return summary
