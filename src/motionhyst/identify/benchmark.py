"""The Bouc-Wen hysteretic benchmark: its data generator and its test sets.

J.P. Noel and M. Schoukens, "Hysteretic benchmark with a dynamic
nonlinearity", Workshop on Nonlinear System Identification Benchmarks, 2016;
M. Schoukens and J.P. Noel, "Three benchmarks addressing open challenges in
nonlinear system identification", IFAC World Congress 2017, pp. 448-453
(data: DOI 10.4121/12967592).

The system is a mass on a linear spring and damper with a Bouc-Wen force,

.. math::

    m \\ddot y + c \\dot y + k y + z = u, \\qquad
    \\dot z = \\alpha \\dot y - \\beta\\left(\\gamma |\\dot y| |z|^{\\nu-1} z
              + \\delta \\dot y |z|^{\\nu}\\right),

force ``u`` [N] in, displacement ``y`` [m] out.  Its training data are made by
the participant with the benchmark's procedure, which this module follows as
published (:func:`benchmark_output`):

1. the input is defined at 15 kHz (the 750 Hz signal upsampled 20x,
   band-limited; a multisine is synthesised at 15 kHz directly,
   :func:`multisine`);
2. Newmark integration at 15 kHz (``a = 1/2``, ``b = 1/4`` for ``y``; the
   trapezoidal rule for ``z``), the implicit step solved by Newton iterations
   (:func:`newmark_bouc_wen`);
3. the output low-pass filtered and decimated to 750 Hz by three 30th-order
   FIR decimation stages (2, 2, 5) (:func:`decimate_fir`), with one extra
   period simulated at the end and dropped so that the filter's edge stays
   out of the record.

The official test sets (``uval_*.mat``, ``yval_*.mat``) are read only by
:func:`load_test_set`; they never enter estimation.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from motionhyst.core.compiled import njit

__all__ = ["benchmark_output", "decimate_fir", "multisine", "newmark_bouc_wen", "training_record"]

#: The benchmark's true system (SI units).
TRUE_PARAMETERS: dict[str, float] = {
    "m": 2.0, "c": 10.0, "k": 5e4, "alpha": 5e4, "beta": 1e3, "gamma": 0.8, "delta": -1.1,
    "nu": 1.0}
#: Sampling frequency of the records [Hz].
FS = 750.0
#: Upsampling factor of the integration (15 kHz).
UPSAMPLE = 20
#: Samples per period of the benchmark's multisine.
PERIOD = 8192
#: Decimation stages of the output filter.
DECIMATION_STAGES = (2, 2, 5)
#: Order of each FIR decimation filter.
FIR_ORDER = 30
#: RMS of the benchmark's output noise [m].
NOISE_RMS = 8e-6
#: Published simulation RMSE on the multisine test [m] (README of the benchmark's test sets).
PUBLISHED_MULTISINE: tuple[tuple[str, str], ...] = (
    ("state-space neural network with grey-box structure (Iacob, Toth, Schoukens)", "7.53e-6"),
    ("polynomial nonlinear state space (PNLSS)", "1.34e-5 to 1.87e-5"),
    ("dynoNet", "4.52e-5"),
    ("best NFIR / NARX / NOBF", "1.63e-4"),
)
#: The official test sets, by name: (input file, output file).
TEST_SETS: dict[str, tuple[str, str]] = {
    "multisine": ("uval_multisine.mat", "yval_multisine.mat"),
    "sinesweep": ("uval_sinesweep.mat", "yval_sinesweep.mat"),
}

#: Options of :func:`motionhyst.identify.input_output.identify_io` for the comparison models.
COMPARISON_OPTIONS: dict[str, dict] = {
    "maxwell-slip": {"n_elements": 3, "substeps": 5, "max_nfev": 3, "start_nfev": 20}}

NEWTON_TOL = 1e-13
NEWTON_MAX_ITER = 50


def multisine(n_periods: int, rng: np.random.Generator, *, rms: float = 50.0,
              f_min: float = 5.0, f_max: float = 150.0, period: int = PERIOD,
              fs: float = FS, upsample: int = UPSAMPLE) -> NDArray[np.float64]:
    """A random-phase multisine at the integration rate ``fs * upsample`` (the benchmark's example).

    Every frequency line from ``floor(f_min / f_res)`` to ``ceil(f_max / f_res)``
    (``f_res = fs / period``) is excited with unit amplitude and a uniformly
    random phase; the signal is scaled to `rms` (sample standard deviation)
    and repeated `n_periods` times.  Being synthesised at the fine rate, it
    is its own band-limited upsampling: ``u[::upsample]`` is the 750 Hz record.

    Parameters
    ----------
    n_periods : int
        Number of periods, >= 1.
    rng : numpy.random.Generator
        Source of the phases.
    rms : float
        RMS of the force [N].
    f_min, f_max : float
        Excited band [Hz].
    period : int
        Samples per period at `fs`.
    fs : float
        Sampling frequency of the record [Hz].
    upsample : int
        Integration samples per record sample.

    Returns
    -------
    ndarray
        ``n_periods * period * upsample`` samples [N].

    Examples
    --------
    >>> import numpy as np
    >>> u = multisine(1, np.random.default_rng(0), period=256)
    >>> u.shape, round(float(np.std(u, ddof=1)), 9)
    ((5120,), 50.0)
    """
    n_int = period * upsample
    f_res = fs / period
    lines = np.arange(int(np.floor(f_min / f_res)), int(np.ceil(f_max / f_res)) + 1)
    lines = lines[lines >= 1]
    spectrum = np.zeros(n_int // 2 + 1, dtype=complex)
    spectrum[lines] = np.exp(2j * np.pi * rng.random(lines.size))
    u = np.fft.irfft(spectrum, n_int)
    u *= rms / np.std(u, ddof=1)
    return np.tile(u, n_periods)


@njit(cache=True)
def _bw_rate(v, z, alpha, beta, gamma, delta, nu):  # pragma: no cover - compiled
    """``z'`` of the benchmark's Bouc-Wen element and its derivatives in ``v`` and ``z``."""
    az = abs(z)
    sz = 1.0 if z > 0.0 else (-1.0 if z < 0.0 else 0.0)
    sv = 1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0)
    if nu == 1.0:
        pn = az
        pn1 = 1.0
    else:
        pn = az ** nu
        pn1 = az ** (nu - 1.0) if az > 0.0 else 0.0
    f = alpha * v - beta * (gamma * abs(v) * pn1 * z + delta * v * pn)
    f_v = alpha - beta * (gamma * sv * pn1 * z + delta * pn)
    f_z = -beta * nu * pn1 * (gamma * abs(v) + delta * v * sz)
    return f, f_v, f_z


@njit(cache=True)
def _newmark(u, h, m, c, k, alpha, beta, gamma, delta, nu, tol, max_iter
             ):  # pragma: no cover - compiled
    n = u.shape[0]
    y_out = np.empty(n)
    a_n, b_n = 0.5, 0.25
    y = 0.0
    v = 0.0
    z = 0.0
    acc = (u[0] - c * v - k * y - z) / m
    fz, _, _ = _bw_rate(v, z, alpha, beta, gamma, delta, nu)
    y_out[0] = y
    worst = 0
    for i in range(1, n):
        # predictor, then Newton on (y, z) at the new time
        y1 = y + h * v + 0.5 * h * h * acc
        z1 = z + h * fz
        it = 0
        while True:
            it += 1
            acc1 = (y1 - y - h * v) / (b_n * h * h) - (0.5 / b_n - 1.0) * acc
            v1 = v + h * ((1.0 - a_n) * acc + a_n * acc1)
            f1, f1_v, f1_z = _bw_rate(v1, z1, alpha, beta, gamma, delta, nu)
            r1 = m * acc1 + c * v1 + k * y1 + z1 - u[i]
            r2 = z1 - z - 0.5 * h * (fz + f1)
            j11 = m / (b_n * h * h) + c * a_n / (b_n * h) + k
            j12 = 1.0
            j21 = -0.5 * h * f1_v * a_n / (b_n * h)
            j22 = 1.0 - 0.5 * h * f1_z
            det = j11 * j22 - j12 * j21
            dy = (r1 * j22 - j12 * r2) / det
            dz = (j11 * r2 - j21 * r1) / det
            y1 -= dy
            z1 -= dz
            if (abs(dy) <= tol * (abs(y1) + 1e-300) and abs(dz) <= tol * (abs(z1) + 1e-300)) \
                    or (dy == 0.0 and dz == 0.0) or it >= max_iter:
                break
        if it > worst:
            worst = it
        acc1 = (y1 - y - h * v) / (b_n * h * h) - (0.5 / b_n - 1.0) * acc
        v = v + h * ((1.0 - a_n) * acc + a_n * acc1)
        acc = acc1
        y = y1
        z = z1
        fz, _, _ = _bw_rate(v, z, alpha, beta, gamma, delta, nu)
        y_out[i] = y
    return y_out, worst


def newmark_bouc_wen(u: ArrayLike, h: float, parameters: dict[str, float] | None = None
                     ) -> NDArray[np.float64]:
    """Displacement of the benchmark's system by its own Newmark scheme, from rest.

    Average acceleration (``a = 1/2``, ``b = 1/4``) for ``y`` and the
    trapezoidal rule ``z(t+h) = z(t) + h/2 (z'(t) + z'(t+h))`` for ``z``; the
    implicit step is solved for ``(y, z)`` by Newton iterations from an
    explicit predictor, until the correction is below ``1e-13`` of the value.
    Second order in `h`.

    Parameters
    ----------
    u : array_like
        Force at the integration instants ``0, h, 2h, ...`` [N].
    h : float
        Step [s].
    parameters : dict, optional
        ``m, c, k, alpha, beta, gamma, delta, nu``; default
        :data:`TRUE_PARAMETERS`.

    Returns
    -------
    ndarray
        ``y`` at the integration instants [m].

    Examples
    --------
    >>> import numpy as np
    >>> y = newmark_bouc_wen(np.linspace(0.0, 10.0, 150001), 1 / 15000)  # 10 s ramp
    >>> round(float(y[-1]) * 1e4, 3)   # nearly static: k y + z = 10 N, z ~ alpha y
    0.993
    """
    p = {**TRUE_PARAMETERS, **(parameters or {})}
    uu = np.ascontiguousarray(u, dtype=float)
    if uu.ndim != 1 or uu.size == 0:
        raise ValueError("u must be a non-empty 1-D array")
    y, _ = _newmark(uu, float(h), p["m"], p["c"], p["k"], p["alpha"], p["beta"], p["gamma"],
                    p["delta"], p["nu"], NEWTON_TOL, NEWTON_MAX_ITER)
    return y


def decimate_fir(y: ArrayLike, r: int, order: int = FIR_ORDER) -> NDArray[np.float64]:
    """Low-pass filter and keep every `r`-th sample, as MATLAB's ``decimate(y, r, 'fir')``.

    The filter is the Hamming-window FIR of `order` with cut-off ``1/r`` of the
    Nyquist frequency, unit gain at DC (``fir1``); its delay of ``order/2``
    samples is removed, so the output sample ``j`` is the filtered signal at
    input sample ``j r``.  The record is extended at both ends by its point
    reflection about the end sample (``2 y[0] - y[order+1:0:-1]``) to start and
    end the filter without a jump.

    Parameters
    ----------
    y : array_like
        Samples, 1-D.
    r : int
        Decimation factor.
    order : int
        FIR order (even).

    Returns
    -------
    ndarray
        ``ceil(len(y) / r)`` samples.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(400) / 400
    >>> out = decimate_fir(np.sin(2 * np.pi * 3 * t), 4)
    >>> out.shape, bool(np.max(np.abs(out - np.sin(2 * np.pi * 3 * t[::4]))) < 1e-3)
    ((100,), True)
    """
    x = np.asarray(y, dtype=float)
    n_taps = order + 1
    if x.size <= n_taps:
        raise ValueError(f"decimate_fir needs more than {n_taps} samples, got {x.size}")
    from scipy.signal import firwin, lfilter  # here: a refusal of the test sets is quicker

    b = firwin(n_taps, 1.0 / r)
    delay = order // 2
    head = 2.0 * x[0] - x[n_taps:0:-1]
    tail = 2.0 * x[-1] - x[-2:-2 - n_taps:-1]
    filtered = lfilter(b, 1.0, np.concatenate([head, x, tail]))[n_taps + delay:]
    return filtered[:x.size:r].copy()


def benchmark_output(u_fine: ArrayLike, parameters: dict[str, float] | None = None, *,
                     upsample: int = UPSAMPLE, fs: float = FS) -> NDArray[np.float64]:
    """The benchmark's 750 Hz output for an input given at the integration rate.

    Newmark integration from rest at ``fs * upsample``
    (:func:`newmark_bouc_wen`), then the three FIR decimation stages
    (:func:`decimate_fir`).  Simulate one period more than needed and drop it
    to keep the filter's edge out (as :func:`training_record` does).

    Parameters
    ----------
    u_fine : array_like
        Force at ``fs * upsample`` [N], a whole number of record samples.
    parameters : dict, optional
        System parameters; default :data:`TRUE_PARAMETERS`.
    upsample : int
        Integration samples per record sample (product of
        :data:`DECIMATION_STAGES` for the benchmark).
    fs : float
        Record sampling frequency [Hz].

    Returns
    -------
    ndarray
        ``len(u_fine) / upsample`` samples of ``y`` [m], noiseless.

    Examples
    --------
    >>> import numpy as np
    >>> u = multisine(1, np.random.default_rng(1), period=512)
    >>> benchmark_output(u).shape
    (512,)
    """
    stages = [f for f in DECIMATION_STAGES] if upsample == UPSAMPLE else _factors(upsample)
    y = newmark_bouc_wen(u_fine, 1.0 / (fs * upsample), parameters)
    for r in stages:
        y = decimate_fir(y, r)
    return y


def _factors(n: int) -> list[int]:
    out, p = [], 2
    while n > 1:
        while n % p == 0:
            out.append(p)
            n //= p
        p += 1
    return out


@dataclass
class Record:
    """An input-output record at 750 Hz: time [s], force [N], displacement [m]."""

    t: NDArray[np.float64]
    u: NDArray[np.float64]
    y: NDArray[np.float64]

    def columns(self) -> dict[str, NDArray[np.float64]]:
        """The signals by CSV column name."""
        return {"time": self.t, "force": self.u, "displacement": self.y}


def training_record(rng: np.random.Generator, n_periods: int = 5, *,
                    noise_rms: float = NOISE_RMS, period: int = PERIOD,
                    parameters: dict[str, float] | None = None) -> Record:
    """One training experiment made by the benchmark's procedure.

    A fresh random-phase multisine (:func:`multisine`, 50 N RMS, 5-150 Hz),
    ``n_periods + 1`` periods simulated from rest (:func:`benchmark_output`),
    the extra last period dropped, and white Gaussian output noise of
    `noise_rms` (band-limited to the 375 Hz Nyquist band) added.

    Parameters
    ----------
    rng : numpy.random.Generator
        Random numbers of the phases and the noise.
    n_periods : int
        Periods of the multisine.
    noise_rms : float
        RMS of the output noise [m].
    period : int
        Samples per period.
    parameters : dict, optional
        System parameters other than the benchmark's.

    Examples
    --------
    >>> import numpy as np
    >>> rec = training_record(np.random.default_rng(2), 2, period=256, noise_rms=0.0)
    >>> rec.u.shape, rec.y.shape, float(rec.t[1])
    ((512,), (512,), 0.0013333333333333333)
    """
    u_fine = multisine(n_periods + 1, rng, period=period)
    y = benchmark_output(u_fine, parameters)
    n = n_periods * period
    y = y[:n] + noise_rms * rng.standard_normal(n)
    return Record(np.arange(n) / FS, u_fine[: n * UPSAMPLE: UPSAMPLE].copy(), y)


def load_test_set(directory: str | Path, name: str) -> Record:
    """One official test set (``multisine`` or ``sinesweep``) from the benchmark's folder.

    Raises ``ValueError`` with one line naming the file when a file is missing
    or unreadable or the two do not match.
    """
    from motionhyst.io.records import read_record

    if name not in TEST_SETS:
        raise ValueError(f"unknown test set {name!r}; expected one of {sorted(TEST_SETS)}")
    arrays = []
    for fname in TEST_SETS[name]:
        path = Path(directory) / fname
        if not path.is_file():
            raise ValueError(f"{path}: no such file (the benchmark's test sets are "
                             f"{', '.join(f for pair in TEST_SETS.values() for f in pair)})")
        key = fname.removesuffix(".mat")
        try:  # the records' reader: MATLAB levels 4 to 7.3, a vector of real numbers
            arr = read_record(path, (key,), columns={key: key})[:, 0]
        except ValueError as exc:
            raise ValueError(f"{path}: cannot read: "
                             f"{str(exc).removeprefix(f'{path}: ')}") from None
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{path}: non-finite data")
        arrays.append(arr)
    u, y = arrays
    if u.size != y.size:
        raise ValueError(f"{directory}: {TEST_SETS[name][0]} and {TEST_SETS[name][1]} differ in "
                         f"length ({u.size} and {y.size})")
    return Record(np.arange(u.size) / FS, u, y)


def generator_check(directory: str | Path) -> float:
    """RMS difference [m] between the generator's output and the official multisine test output.

    The official test input (one period) is upsampled by zero-padding its
    spectrum (it is a multisine below 150 Hz: exact), simulated for three
    periods from rest and the middle period compared.  Only the test's input
    and output are used, nothing is estimated.
    """
    test = load_test_set(directory, "multisine")
    n = test.u.size
    spec = np.zeros(n * UPSAMPLE // 2 + 1, dtype=complex)
    spec[: n // 2] = np.fft.rfft(test.u)[: n // 2]
    u_fine = np.fft.irfft(spec, n * UPSAMPLE) * UPSAMPLE
    y = benchmark_output(np.tile(u_fine, 3))
    return float(np.sqrt(np.mean((y[n:2 * n] - test.y) ** 2)))


def run_benchmark(directory: str | Path, *, seed: int = 0, n_experiments: int = 2,
                  n_periods: int = 5, models: tuple[str, ...] = ("bouc-wen", "maxwell-slip"),
                  progress=None) -> dict:
    """The Bouc-Wen benchmark end to end: training data, identification, test RMSE.

    Training: `n_experiments` experiments of `n_periods` periods made by the
    benchmark's procedure (:func:`training_record`, fresh multisines and noise
    from `seed`).  Each model in `models` is identified from them alone
    (:func:`motionhyst.identify.input_output.identify_io`, from rest), then simulated from
    the official test inputs (the multisine as its periodic steady state, the
    sine sweep from rest) and scored by the RMS of the simulation error over
    each whole test set.  The Maxwell-slip comparison (3 elements) is
    refined with a finite-difference Jacobian, 5 integration steps per sample
    and at most 20 evaluations per start and 3 on the full records (:data:`COMPARISON_OPTIONS`):
    its structure, not its convergence, limits it (a Maxwell-slip link
    saturates; the benchmark's Bouc-Wen force stiffens, ``gamma + delta < 0``).

    Returns
    -------
    dict
        ``{"training", "generator_check_rms", "models": [{"model", "multisine_rmse",
        "sinesweep_rmse", "identification_s", "simulation_s", "fit_rms",
        "identification"}], "published"}``.
    """
    import time

    tests = {name: load_test_set(directory, name) for name in TEST_SETS}
    from motionhyst.identify.input_output import IORecord, identify_io  # once they are read
    say = progress or (lambda msg: None)
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    records = []
    for i in range(n_experiments):
        rec = training_record(rng, n_periods)
        records.append(IORecord(rec.t, rec.u, rec.y, f"experiment {i + 1}"))
    gen_s = time.perf_counter() - t0
    say(f"training data: {n_experiments} x {n_periods} periods of {PERIOD} samples "
        f"({gen_s:.1f} s)")
    out_models = []
    for model in models:
        t0 = time.perf_counter()
        fit = identify_io(records, model, **COMPARISON_OPTIONS.get(model, {}))
        ident_s = time.perf_counter() - t0
        say(f"{model}: identified in {ident_s:.1f} s, fit RMS {fit.fit_rms:.3g} m")
        system = fit.system()
        row = {"model": model, "identification_s": ident_s, "fit_rms": fit.fit_rms,
               "identification": fit.to_dict()}
        t0 = time.perf_counter()
        for name, test in tests.items():
            y = system.simulate(test.t, test.u, periodic=(name == "multisine")).displacement
            row[f"{name}_rmse"] = float(np.sqrt(np.mean((y - test.y) ** 2)))
        row["simulation_s"] = time.perf_counter() - t0
        say(f"{model}: test RMSE multisine {row['multisine_rmse']:.3g} m, sine sweep "
            f"{row['sinesweep_rmse']:.3g} m")
        out_models.append(row)
    return {"training": {"experiments": n_experiments, "periods": n_periods,
                         "samples_per_period": PERIOD, "noise_rms": NOISE_RMS, "seed": seed,
                         "generation_s": gen_s},
            "generator_check_rms": generator_check(directory),
            "models": out_models,
            "published": [{"method": m, "multisine_rmse": v} for m, v in PUBLISHED_MULTISINE]}
