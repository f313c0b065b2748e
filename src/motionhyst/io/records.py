"""Measured records as engineers have them: CSV or MATLAB ``.mat`` files, columns mapped and scaled.

Every command that reads a record (``identify``, ``predict``, ``simulate``'s
reference, a measured plant's frequency response) reads it through
:func:`read_record`, which takes

- a CSV file with a header row (the dialects of :mod:`motionhyst.io.csvdata`:
  byte-order marks, comma, semicolon or tab, decimal commas, names in any case);
- a MATLAB ``.mat`` file: level 4 and 5 (MATLAB's ``-v4``, ``-v6``, ``-v7``)
  through :func:`scipy.io.loadmat`, version 7.3 (HDF5) through :mod:`h5py`.
  Each column is a numeric vector variable (``n x 1`` or ``1 x n``; any real
  numeric class), a field of a structure written ``name.field``; names match
  exactly, else ignoring case when that is unambiguous.  The file's kind is
  found from its content, not only its name: a text file named ``.mat`` is an
  error, a ``.mat`` file named otherwise is read;
- a numpy array (the columns in the order asked for), a pandas DataFrame or a
  mapping of columns (names matched as in a CSV header).

Files name their signals as their software does (the EMPS benchmark's
``DATA_EMPS.mat``: ``t``, ``qm``, ``vir``).  A column map (``--columns
time=t,force=vir,displacement=qm`` on the command line,
:func:`parse_columns`) says which of the file's columns is which quantity
the command needs, and a scale (``--scale force=35.15065``,
:func:`parse_scale`) multiplies a quantity by a gain, here the drive's
35.15065 N/V that turns the controller's output in volts into the force
in newtons.

Time stamps written by a data logger jitter (EMPS: 2e-5 of the step).
Where a command needs a uniform grid (``identify --record input-output``,
``predict``), it fits the nearest one to all the stamps and accepts every
stamp within 0.05 of a sampling interval of it
(:data:`motionhyst.time.openloop.STAMP_TOLERANCE`, :func:`motionhyst.time.openloop.check_record`);
a record whose stamps stray further (a dropped or repeated sample) is refused,
naming the worst stamp.

Two unit slips show in the values and are a warning naming the column: positions
beyond :data:`MAX_POSITION` (100 m: a record in millimetres of a stroke over
100 mm, or in micrometres) and time steps finer than :data:`MIN_TIME_STEP`
(2e-8 s: a record stamped in days, sampled at 1 kHz or faster).  Others, a
short stroke in millimetres or time in hours, look like values a stage may have.

Every problem is a :class:`RecordError` (a ``ValueError``) with one line
naming the file: not a CSV or ``.mat`` file, a missing column or variable
(the message lists those found), a variable that is not a numeric vector,
columns of different lengths, a column map or scale naming a quantity the
command does not read.
"""

from __future__ import annotations

import codecs
import math
import os
import struct
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.budget import BudgetError
from motionhyst.core.validation import MAGNITUDES
from motionhyst.io._mat_sizes import declared_values
from motionhyst.io.csvdata import (
    CSVError,
    Source,
    data_rows,
    describe,
    normalize_name,
    read_columns,
    read_header,
)
from motionhyst.io.inputs import input_problem

_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
_MAT_TEXT_HEADER = b"MATLAB"
_MAT_CLASSES = {"double", "single", "int8", "uint8", "int16", "uint16", "int32", "uint32",
                "int64", "uint64", "logical"}
_CONTAINERS = {"struct", "cell", "object"}
_CLASS_WORDS = {"cell": "a cell array", "char": "text (char)", "struct": "a structure",
                "function_handle": "a function handle"}


class RecordError(CSVError):
    """A record that cannot be read as asked: one line naming the file and the problem.

    Examples
    --------
    >>> from motionhyst.io.records import RecordError, parse_columns
    >>> try:
    ...     parse_columns("time")
    ... except RecordError as err:
    ...     print("RecordError:", err)
    RecordError: --columns: 'time' is not NAME=COLUMN (for example time=t,force=vir,...)
    """


# ------------------------------------------------------------------ the command-line options
def _pairs(text: str, option: str, example: str) -> list[tuple[str, str]]:
    pairs = []
    for item in str(text).split(","):
        if not item.strip():
            continue
        name, sep, value = item.partition("=")
        if not sep or not name.strip() or not value.strip():
            raise RecordError(f"{option}: {item.strip()!r} is not NAME=COLUMN (for example "
                              f"{example})" if option == "--columns" else
                              f"{option}: {item.strip()!r} is not NAME=GAIN (for example "
                              f"{example})")
        pairs.append((normalize_name(name), value.strip()))
    if not pairs:
        raise RecordError(f"{option}: empty; give NAME=VALUE pairs (for example {example})")
    seen: set[str] = set()
    for name, _ in pairs:
        if name in seen:
            raise RecordError(f"{option}: {name!r} is given twice")
        seen.add(name)
    return pairs


def parse_columns(text: str) -> dict[str, str]:
    """The column map of ``--columns``: quantity -> the file's name for it.

    Parameters
    ----------
    text : str
        ``NAME=COLUMN`` pairs separated by commas; NAME is a quantity the
        command reads (``time``, ``force``, ``displacement``, ...), COLUMN the
        CSV column or MATLAB variable (``data.qm`` for a structure's field).

    Returns
    -------
    dict
        Quantity (lower case) -> column name as given.

    Raises
    ------
    RecordError
        A pair without ``=``, an empty side, a quantity given twice.

    Examples
    --------
    >>> parse_columns("time=t,force=vir,displacement=qm")
    {'time': 't', 'force': 'vir', 'displacement': 'qm'}
    """
    return dict(_pairs(text, "--columns", "time=t,force=vir,..."))


def parse_scale(text: str) -> dict[str, float]:
    """The gains of ``--scale``: quantity -> the factor its column is multiplied by.

    Parameters
    ----------
    text : str
        ``NAME=GAIN`` pairs separated by commas; GAIN a finite non-zero number
        (negative to flip a sign).

    Returns
    -------
    dict
        Quantity (lower case) -> gain.

    Raises
    ------
    RecordError
        A pair that is not ``NAME=GAIN``, a gain that is not a finite non-zero
        number, a quantity given twice.

    Examples
    --------
    >>> parse_scale("force=35.15065")
    {'force': 35.15065}
    """
    out = {}
    for name, value in _pairs(text, "--scale", "force=35.15065"):
        try:
            gain = float(value)
        except ValueError:
            raise RecordError(f"--scale: {name}={value}: the gain must be a number") from None
        if not math.isfinite(gain) or gain == 0.0:
            raise RecordError(f"--scale: {name}={value}: the gain must be finite and non-zero")
        out[name] = gain
    return out


def _check_keys(given: Mapping | None, names: Sequence[str], option: str, where: str) -> None:
    for key in given or {}:
        if key not in names:
            raise RecordError(f"{where}: {option} names {key!r}, which is not read here; this "
                              f"record's columns are {','.join(names)}")


# ------------------------------------------------------------------ the file's kind
def _is_path(source: Source) -> bool:
    return isinstance(source, str | os.PathLike)


def _head(path: Path, n: int = 128) -> bytes:
    """The first `n` bytes of a record's file, which say its kind.  Only the file's type is
    checked here: what reading it takes depends on the kind (a CSV file's text parsed
    whole, ``CSV_EXPANSION`` times its size, checked by its reader; a MATLAB file's
    variables read one by one, the others skipped, each checked by :func:`_check_size`
    from the size it declares), not on the file's size alone."""
    why = input_problem(path, 0.0)
    if why:
        raise RecordError(f"cannot read {path}: {why}")
    try:
        with path.open("rb") as fh:
            return fh.read(n)
    except FileNotFoundError:
        raise RecordError(f"cannot read {path}: no such file") from None
    except IsADirectoryError:
        raise RecordError(f"cannot read {path}: it is a folder") from None
    except OSError as exc:
        raise RecordError(f"cannot read {path}: {exc.strerror or exc}") from None


def is_mat_file(source: Source) -> bool:
    """Whether `source` is read as a MATLAB file: its content says so, or its name ends ``.mat``.

    Parameters
    ----------
    source : str, os.PathLike, file or DataFrame
        A record's file (anything else is not a MATLAB file).

    Examples
    --------
    >>> is_mat_file("DATA_EMPS.mat"), is_mat_file("record.csv")
    (True, False)
    """
    if not _is_path(source):
        return False
    path = Path(source)
    if path.suffix.lower() == ".mat":
        return True
    try:
        head = _head(path, 520)
    except RecordError:
        return False  # the reader says why
    return (head.startswith(_MAT_TEXT_HEADER) or _HDF5_SIGNATURE in (head[:8], head[512:520])
            or _is_level4(head))


def _is_level4(head: bytes) -> bool:
    """Whether `head` opens a MATLAB level-4 file (``-v4``, no text header): a first matrix
    header of five integers (type MOPT, rows, columns, imaginary flag, name length) that
    MATLAB writes, and the name it announces.  For a file not named ``.mat``: scipy's
    ``matfile_version`` calls level 4 any file with a zero among its first four bytes (most
    binary files), which is too loose to decide that a file is MATLAB's."""
    if len(head) < 21:
        return False
    for order in "<>":
        mopt, rows, cols, imag, length = struct.unpack(order + "5i", head[:20])
        m, o, p, t = mopt // 1000, mopt // 100 % 10, mopt // 10 % 10, mopt % 10
        if not (0 <= mopt < 5000 and m <= 4 and o == 0 and p <= 5 and t <= 2
                and rows >= 0 and cols >= 0 and imag in (0, 1) and 2 <= length <= 64):
            continue
        name = head[20:20 + length]
        if len(name) == length and name.endswith(b"\0") and name[:-1].isascii() \
                and name[:-1].decode().isprintable():
            return True
    return False


def _mat_kind(path: Path) -> str:
    """``"hdf5"`` (MATLAB 7.3) or ``"scipy"`` (levels 4 and 5); RecordError for anything else."""
    head = _head(path, 520)
    if not head:
        raise RecordError(f"{path}: empty file, not a MATLAB .mat file")
    if _HDF5_SIGNATURE in (head[:8], head[512:520]):
        return "hdf5"
    if head.startswith(_MAT_TEXT_HEADER):
        return "scipy"
    if _is_level4(head):  # level 4: no text header
        return "scipy"
    what = "a text file"
    if not _looks_like_text(head):  # scipy's own test, looser than the header's: a file
        from scipy.io.matlab import matfile_version  # named .mat is given to scipy's reader

        try:
            major, _ = matfile_version(str(path))
        except Exception:  # scipy raises several kinds for a file that is not MATLAB's
            major = None
        if major == 0:
            return "scipy"
        what = "an unknown format"
    raise RecordError(f"{path}: not a MATLAB .mat file ({what}); a CSV record must be named .csv")


def _check_text(source: Source) -> None:
    """A CSV path must hold text: a binary file is refused before its bytes reach a message."""
    if not _is_path(source) or Path(source).is_dir():
        return
    path = Path(source)
    if not path.exists():
        return  # the CSV reader says so
    head = _head(path, 4096)
    if head.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        return
    if b"\0" in head:
        raise RecordError(f"{path}: not a CSV file (binary data, and not a MATLAB .mat file)")


def _looks_like_text(head: bytes) -> bool:
    try:
        text = head.decode("utf-8")
    except UnicodeDecodeError:
        try:
            text = head.decode("utf-16")
        except UnicodeDecodeError:
            return False
    return all(c.isprintable() or c in "\r\n\t\ufeff" for c in text)


# ------------------------------------------------------------------ MATLAB files
def _resolve(name: str, available: Sequence[str], path: Path, what: str = "variable") -> str:
    """`name` among `available`: exactly, else the one equal ignoring case."""
    if name in available:
        return name
    folded = [a for a in available if a.lower() == name.lower()]
    if len(folded) == 1:
        return folded[0]
    shown = ", ".join(available) if available else "none"
    if folded:
        raise RecordError(f"{path}: {what} {name!r} is ambiguous ignoring case "
                          f"({', '.join(folded)})")
    err = RecordError(f"{path}: no {what} {name!r} (the file has: {shown})")
    err.missing = name
    raise err


def _vector(path: Path, name: str, value, matlab_class: str | None) -> NDArray[np.float64]:
    """A MATLAB variable as a float vector, or a one-line error saying what it is."""
    if matlab_class is not None and matlab_class not in _MAT_CLASSES:
        what = _CLASS_WORDS.get(matlab_class, f"of class {matlab_class}")
        raise RecordError(f"{path}: variable {name!r} is {what}, not a numeric vector")
    arr = np.asarray(value)
    if arr.dtype.kind not in "biuf":
        kind = "complex" if arr.dtype.kind == "c" else "non-numeric"
        raise RecordError(f"{path}: variable {name!r} is {kind}, not a real numeric vector")
    shape = "x".join(str(s) for s in arr.shape) or "1x1"
    if arr.size == 0:
        raise RecordError(f"{path}: variable {name!r} is empty")
    if sum(s > 1 for s in arr.shape) > 1:
        raise RecordError(f"{path}: variable {name!r} is a {shape} matrix; each column must be "
                          f"a vector (n x 1 or 1 x n)")
    return np.asarray(arr, dtype=np.float64).ravel()


def _check_size(path: Path, name: str, values: int, total: list[int]) -> None:
    """Refuse, before it is read, a variable whose values (with those already read, `total`)
    would exceed the memory budget: a compressed file declares its size, and a few MB of
    zeros can unpack into GBs."""
    from motionhyst.core.budget import check_memory

    total[0] += values
    check_memory(VALUE_BYTES * total[0], f"{path}: cannot read variable {name!r}: reading its "
                 f"{values} values", "give a smaller file")


def _read_scipy(path: Path, wanted: Sequence[str]) -> list[NDArray[np.float64]]:
    from scipy.io import loadmat, whosmat

    try:
        whos = whosmat(str(path))
        info = {n: cls for n, _, cls in whos}
        try:
            tops = list(dict.fromkeys(_resolve(w.split(".")[0], list(info), path)
                                      for w in wanted))
        except RecordError:
            loadmat(str(path))  # a file cut short lists only its first variables: say so
            raise
        for w in wanted:  # a variable of another class is refused before it is read
            top = _resolve(w.split(".")[0], list(info), path)
            if "." not in w and info[top] not in _MAT_CLASSES | {"struct"}:
                _vector(path, top, None, info[top])
        total = [0]
        for name, shape, cls in whos:
            if name in tops and cls not in _CONTAINERS:
                _check_size(path, name, math.prod(shape), total)
        # whosmat lists a structure or cell as 1x1: the sizes its arrays declare, walked
        declared_values(path, [n for n, _, cls in whos if n in tops and cls in _CONTAINERS],
                        lambda name, values: _check_size(path, name, values, total))
        data = loadmat(str(path), variable_names=tops, simplify_cells=True)
    except (RecordError, BudgetError):
        raise
    except Exception as exc:  # scipy's many ways to fail on a damaged file
        raise RecordError(f"{path}: cannot read as a MATLAB file ({_one_line(exc)})") from None
    out = []
    for w in wanted:
        top, *fields = w.split(".")
        top = _resolve(top, list(info), path)
        value, cls, name = data[top], info[top], top
        for field in fields:
            if not isinstance(value, dict):
                raise RecordError(f"{path}: variable {name!r} is not a structure (no field "
                                  f"{field!r})")
            key = _resolve(field, list(value), path, f"field of {name!r}:")
            value, cls, name = value[key], None, f"{name}.{key}"
        if isinstance(value, dict):
            raise RecordError(f"{path}: variable {name!r} is a structure; name one of its fields "
                              f"({', '.join(value)}) as {name}.FIELD")
        if isinstance(value, str):
            raise RecordError(f"{path}: variable {name!r} is text, not a numeric vector")
        if isinstance(value, list):
            raise RecordError(f"{path}: variable {name!r} is a cell array, not a numeric vector")
        out.append(_vector(path, name, value, cls))
    return out


def _matlab_class(obj) -> str | None:
    cls = obj.attrs.get("MATLAB_class")
    if cls is None:
        return None
    return cls.decode() if isinstance(cls, bytes) else str(cls)


def _read_hdf5(path: Path, wanted: Sequence[str]) -> list[NDArray[np.float64]]:
    import h5py

    try:
        fh = h5py.File(path, "r")
    except Exception as exc:  # h5py raises OSError subclasses with long texts
        raise RecordError(f"{path}: cannot read as a MATLAB 7.3 file ({_one_line(exc)})") from None
    with fh:
        out, total = [], [0]
        for w in wanted:
            group, name = fh, ""
            parts = w.split(".")
            for i, part in enumerate(parts):
                names = [k for k in group if not k.startswith("#")]
                what = "variable" if i == 0 else f"field of {name!r}:"
                key = _resolve(part, names, path, what)
                name = f"{name}.{key}" if name else key
                obj = group[key]
                if i < len(parts) - 1:
                    if not isinstance(obj, h5py.Group):
                        raise RecordError(f"{path}: variable {name!r} is not a structure (no "
                                          f"field {parts[i + 1]!r})")
                    group = obj
            if isinstance(obj, h5py.Group):
                fields = ", ".join(k for k in obj if not k.startswith("#"))
                raise RecordError(f"{path}: variable {name!r} is a structure; name one of its "
                                  f"fields ({fields}) as {name}.FIELD")
            cls = _matlab_class(obj)
            if obj.attrs.get("MATLAB_empty"):
                raise RecordError(f"{path}: variable {name!r} is empty")
            if cls is not None and cls not in _MAT_CLASSES:
                what = _CLASS_WORDS.get(cls, f"of class {cls}")
                raise RecordError(f"{path}: variable {name!r} is {what}, not a numeric vector")
            _check_size(path, name, obj.size, total)
            try:
                value = obj[()]
            except Exception as exc:
                raise RecordError(f"{path}: cannot read variable {name!r} "
                                  f"({_one_line(exc)})") from None
            if value.dtype.names:  # MATLAB stores complex numbers as a compound (real, imag)
                raise RecordError(f"{path}: variable {name!r} is complex, not a real numeric "
                                  f"vector")
            out.append(_vector(path, name, np.asarray(value).T, cls))  # MATLAB's shape
    return out


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


def _mat_names(path: Path) -> list[str]:
    """The variables of a MATLAB file (a structure's fields as ``name.field``)."""
    if _mat_kind(path) == "hdf5":
        import h5py

        try:
            with h5py.File(path, "r") as fh:
                names = []
                for k in fh:
                    if k.startswith("#"):
                        continue
                    if isinstance(fh[k], h5py.Group):
                        names += [f"{k}.{f}" for f in fh[k] if not f.startswith("#")]
                    else:
                        names.append(k)
                return names
        except Exception as exc:
            raise RecordError(f"{path}: cannot read as a MATLAB 7.3 file "
                              f"({_one_line(exc)})") from None
    from scipy.io import whosmat

    try:
        return [n for n, _, _ in whosmat(str(path))]
    except Exception as exc:
        raise RecordError(f"{path}: cannot read as a MATLAB file ({_one_line(exc)})") from None


def _read_mat(path: Path, wanted: Sequence[str]) -> NDArray[np.float64]:
    reader = _read_hdf5 if _mat_kind(path) == "hdf5" else _read_scipy
    columns = reader(path, wanted)
    lengths = {w: c.size for w, c in zip(wanted, columns, strict=True)}
    if len(set(lengths.values())) > 1:
        raise RecordError(f"{path}: the variables differ in length (" + ", ".join(
            f"{w} {n}" for w, n in lengths.items()) + ")")
    return np.ascontiguousarray(np.column_stack(columns), dtype=np.float64)


# ------------------------------------------------------------------ sizes before reading
SIZED_UNREAD_BYTES = 8 << 20
"""Record files of this many bytes (all together) and more are sized before they are read
(:func:`check_unread`): reading 8 MB of CSV takes about 0.4 s and 20 MB; a smaller record is
read and the command's estimate checked after."""


def _mat_samples(path: Path, wanted: Sequence[str]) -> int | None:
    """The values of the longest of the variables `wanted` a MATLAB file declares (None when
    one of them is not found as asked: the reader says why)."""
    counts: dict[str, int] = {}
    if _mat_kind(path) == "hdf5":
        import h5py

        with h5py.File(path, "r") as fh:
            for w in wanted:
                obj = fh
                for part in w.split("."):
                    if not isinstance(obj, h5py.Group):
                        return None
                    names = [k for k in obj if not k.startswith("#")]
                    obj = obj[_resolve(part, names, path)]
                if isinstance(obj, h5py.Group):
                    return None
                counts[w] = int(obj.size)
        return max(counts.values(), default=None)
    from scipy.io import whosmat

    whos = whosmat(str(path))
    shapes = {n: shape for n, shape, cls in whos if cls not in _CONTAINERS}
    fields: dict[str, int] = {}
    tops = {_resolve(w.split(".")[0], [n for n, _, _ in whos], path) for w in wanted if "." in w}
    declared_values(path, tops - set(shapes),  # the structures named: their fields walked
                    lambda name, values: fields.setdefault(name.lower(), values))
    for w in wanted:
        top = _resolve(w.split(".")[0], [n for n, _, _ in whos], path)
        if "." not in w and top in shapes:
            counts[w] = math.prod(shapes[top])
        elif f"{top}{w[len(top):]}".lower() in fields:
            counts[w] = fields[f"{top}{w[len(top):]}".lower()]
        else:
            return None
    return max(counts.values(), default=None)


def record_samples(source: Source, names: Sequence[str],
                   columns: Mapping[str, str] | None = None) -> tuple[int, bool] | None:
    """The samples of a record file before its values are read, and whether the count is
    exact: a MATLAB file's from the sizes its variables declare, a CSV file's from its lines
    (:func:`~motionhyst.io.csvdata.data_rows`: counted up to 64 MB, a line of spaces
    counting, estimated from lines sampled across a larger file).

    Parameters
    ----------
    source : str, os.PathLike, ndarray or DataFrame
        The record (anything but a file: None).
    names : sequence of str
        The quantities read, as for :func:`read_record`.
    columns : mapping, optional
        Quantity -> the file's name for it.

    Returns
    -------
    (int, bool) or None
        The samples and whether they are exact; None where a file does not say (a column or
        variable not found: its reader says so).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from scipy.io import savemat
    >>> path = Path(tempfile.mkdtemp()) / "axis.mat"
    >>> savemat(path, {"t": np.zeros((5000, 1)), "vir": np.zeros(5000), "qm": np.zeros(5000)})
    >>> record_samples(path, ("time", "force"), {"time": "t", "force": "vir"})
    (5000, True)
    >>> record_samples(np.zeros((10, 2)), ("time", "force")) is None
    True
    """
    if not _is_path(source):
        return None
    wanted = [dict(columns or {}).get(n, n) for n in names]
    try:
        if is_mat_file(source):
            n = _mat_samples(Path(source), wanted)
            return None if n is None else (n, True)
        _check_text(source)
        if not {normalize_name(w) for w in wanted} <= set(read_header(source)):
            return None
        return data_rows(source)
    except Exception:  # a damaged file, a name not found: its reader says what is wrong
        return None


def check_unread(sources: Sequence[Source], names: Sequence[str],
                 check: Callable[[list[int]], None], *,
                 columns: Mapping[str, str] | None = None) -> None:
    """Size record files before they are read (:func:`record_samples`) and run a command's
    estimate from their samples, `check`, on them: a refusal comes before the reading,
    named with the files' samples.  Files of fewer than :data:`SIZED_UNREAD_BYTES` in all
    are left to the estimate after their reading.

    Parameters
    ----------
    sources : sequence
        The records (anything but files is left alone).
    names : sequence of str
        The quantities read.
    check : callable
        Called with each record's samples; raises a ``ValueError`` (a
        :class:`~motionhyst.core.budget.BudgetError`) to refuse.
    columns : mapping, optional
        Quantity -> the files' names for it.

    Raises
    ------
    ValueError
        One line: the files, their samples (``about`` where estimated) and what `check` said.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from scipy.io import savemat
    >>> from motionhyst.core.budget import BudgetError, check_memory, set_max_memory
    >>> set_max_memory(1 << 30)
    >>> folder = tempfile.TemporaryDirectory()
    >>> path = Path(folder.name) / "long.mat"
    >>> savemat(path, {"time": np.zeros(2_000_000), "force": np.zeros(2_000_000)})
    >>> def search(sizes):
    ...     check_memory(700.0 * sum(sizes), f"a search of {sum(sizes)} samples", "fewer")
    >>> try:
    ...     check_unread([path], ("time", "force"), search)
    ... except BudgetError as exc:
    ...     print(str(exc).replace(str(path), "long.mat"))      # doctest: +ELLIPSIS
    long.mat (2000000 samples, not read yet): a search of 2000000 samples needs 1.4 GB, ...
    >>> set_max_memory(None)
    >>> folder.cleanup()
    """
    paths = [Path(s) for s in sources if _is_path(s)]
    if len(paths) < len(sources) or not paths:
        return
    try:
        total = sum(p.stat().st_size for p in paths)
    except (OSError, ValueError):
        return  # the reader says why
    if total < SIZED_UNREAD_BYTES:
        return
    counts = [record_samples(p, names, columns) for p in paths]
    if any(c is None for c in counts):
        return
    sizes = [n for n, _ in counts]
    exact = all(e for _, e in counts)
    n = sum(sizes)
    said = f"{n} samples" if exact else f"about {n} samples"
    files = str(paths[0]) if len(paths) == 1 else f"{len(paths)} records"
    try:
        check(sizes)
    except BudgetError as exc:
        cause = exc.cause.removeprefix(f"{files}: ")  # the file named once
        raise BudgetError(f"{files} ({said}, not read yet): {cause}", exc.remedy) from None
    except ValueError as exc:
        raise ValueError(f"{files} ({said}, not read yet): {exc}") from None


# ------------------------------------------------------------------ the readers
def record_columns(source: Source, columns: Mapping[str, str] | None = None) -> list[str]:
    """The quantities a record offers: its column (or variable) names, mapped by `columns`.

    A name `columns` maps to is reported as the quantity (``t`` as ``time``
    with ``columns={"time": "t"}``); other names normalised as a CSV header's
    (lower case, see :func:`motionhyst.io.csvdata.normalize_name`).

    Parameters
    ----------
    source : str, os.PathLike, file or DataFrame
        The record: a CSV or MATLAB file, or a table already read.
    columns : mapping of str to str, optional
        Quantity -> the record's column (or variable) name.

    Examples
    --------
    >>> import pandas as pd
    >>> record_columns(pd.DataFrame({"t": [0.0], "qm": [0.0], "vir": [0.0]}),
    ...                {"time": "t", "displacement": "qm"})
    ['time', 'displacement', 'vir']
    """
    if _is_path(source) and is_mat_file(source):
        names = _mat_names(Path(source))
        back, fields = {}, []
        for quantity, col in (columns or {}).items():
            try:
                back[_resolve(col, names, Path(source))] = quantity
            except RecordError:
                # a MATLAB 5 structure is listed whole: its field is read (or refused) later
                struct = col.split(".", 1)[0].lower() if "." in col else None
                if struct is not None and struct in (n.lower() for n in names):
                    fields.append(quantity)
        return [back.get(n, normalize_name(n)) for n in names] + fields
    _check_text(source)
    try:
        names = read_header(source)
    except CSVError as exc:
        raise RecordError(str(exc)) from None
    back = {normalize_name(col): quantity for quantity, col in (columns or {}).items()}
    return [back.get(n, n) for n in names]


def read_record(source: Source, names: Sequence[str], *,
                columns: Mapping[str, str] | None = None,
                scale: Mapping[str, float] | None = None) -> NDArray[np.float64]:
    """The quantities `names` of a record, as a float array of shape ``(rows, len(names))``.

    Parameters
    ----------
    source : str, Path, ndarray, DataFrame or mapping
        A CSV or MATLAB ``.mat`` file (see the module docstring), a DataFrame
        or mapping of columns, or a 2-D array whose columns are `names` in order.
    names : sequence of str
        The quantities wanted, lower case (``("time", "force", "displacement")``).
    columns : mapping, optional
        Quantity -> the file's name for it (:func:`parse_columns`); a quantity
        not mapped is read under its own name.  Each key must be in `names`.
    scale : mapping, optional
        Quantity -> gain its column is multiplied by (:func:`parse_scale`);
        each key must be in `names`.

    Returns
    -------
    ndarray
        Float64, C-contiguous, one column per name.  Non-finite values are
        kept as read; callers check them in their own terms.

    Raises
    ------
    RecordError
        One line naming the source (see the module docstring).

    Examples
    --------
    A MATLAB file written as the EMPS benchmark's, read with its names mapped
    and the controller's output in volts scaled to newtons:

    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> from scipy.io import savemat
    >>> path = Path(tempfile.mkdtemp()) / "axis.mat"
    >>> t = np.arange(4) * 1e-3
    >>> savemat(path, {"t": t[:, None], "vir": np.array([[0.1], [0.2], [0.0], [-0.1]]),
    ...                "qm": np.zeros((4, 1))})
    >>> data = read_record(path, ("time", "force", "displacement"),
    ...                    columns={"time": "t", "force": "vir", "displacement": "qm"},
    ...                    scale={"force": 35.15065})
    >>> data[:, 1]
    array([ 3.515065,  7.03013 ,  0.      , -3.515065])
    """
    names = tuple(names)
    where = describe(source)
    _check_keys(columns, names, "--columns", where)
    _check_keys(scale, names, "--scale", where)
    columns = dict(columns or {})
    wanted = [columns.get(n, n) for n in names]
    if len(set(map(str.lower, wanted))) < len(wanted):
        raise RecordError(f"{where}: --columns reads one column as two quantities ("
                          + ", ".join(f"{n}={w}" for n, w in zip(names, wanted, strict=True))
                          + ")")
    unmapped = [n for n in names if n not in columns]
    if _is_path(source) and is_mat_file(source):
        try:
            data = _read_mat(Path(source), wanted)
        except RecordError as exc:
            missing = getattr(exc, "missing", None)
            if missing in unmapped:
                raise RecordError(f"{exc}; map the file's name for it with --columns "
                                  f"{missing}=NAME") from None
            raise
    else:
        if columns and isinstance(source, np.ndarray):
            raise RecordError(f"{where}: --columns maps names, and an array has none; give its "
                              f"columns in the order {','.join(names)}")
        _check_text(source)
        try:
            data = read_columns(source, [normalize_name(w) for w in wanted])
        except RecordError:
            raise
        except CSVError as exc:
            hint = ("; map the file's names with --columns NAME=COLUMN,..." if unmapped
                    and "missing column" in str(exc) and _is_path(source) else "")
            raise RecordError(f"{exc}{hint}") from None
    for i, n in enumerate(names):
        gain = (scale or {}).get(n)
        if gain is not None:
            data[:, i] *= gain
    _check_magnitudes(data, names, where)
    _check_units(data, names, where)
    return data


def _check_magnitudes(data: NDArray[np.float64], names: Sequence[str], where: str) -> None:
    """A column whose largest magnitude lies outside the magnitudes motionhyst computes with
    (:data:`~motionhyst.core.validation.MAGNITUDES`; a column of zeros is allowed) is a
    RecordError naming it: a unit slip, or a column that is not the quantity named."""
    with np.errstate(invalid="ignore"):  # the largest magnitude without a copy of the data
        peaks = (np.maximum(np.abs(np.max(data, axis=0)), np.abs(np.min(data, axis=0)))
                 if data.size else [])
    for name, peak in zip(names, peaks, strict=False):
        if peak != 0.0 and np.isfinite(peak) and not MAGNITUDES[0] <= peak <= MAGNITUDES[1]:
            raise RecordError(f"{where}: {name} reaches {peak:.3g}: outside the magnitudes "
                              f"{MAGNITUDES[0]:g} to {MAGNITUDES[1]:g} (SI units) that "
                              f"motionhyst computes with (its unit? --scale {name}=GAIN)")


VALUE_BYTES = 16
"""Memory a MATLAB variable's value takes as it is read [bytes]: its own array (up to 8
bytes) and its float64 copy."""

MAX_POSITION = 100.0
"""Largest position [m] of a motion stage's record in metres: beyond, a warning (a record in
millimetres of a stroke over 100 mm, or in micrometres)."""

MIN_TIME_STEP = 2e-8
"""Finest time step [s] of a record (50 MHz) without a warning: a record stamped in days and
sampled at 1 kHz or faster has finer steps (1.16e-8 "s" at 1 kHz)."""


def _check_units(data: NDArray[np.float64], names: Sequence[str], where: str) -> None:
    """Warn of the unit slips the values show: positions beyond :data:`MAX_POSITION`, time
    steps finer than :data:`MIN_TIME_STEP` (each a question: the values may be meant)."""
    from motionhyst.core.warnings import warn

    columns = dict(zip(names, data.T, strict=False))
    y = columns.get("displacement")
    if y is not None and y.size:
        with np.errstate(invalid="ignore"):
            peak = float(np.max(np.abs(y)))
        if peak > MAX_POSITION:
            warn(f"{where}: displacement reaches {peak:.3g} m, beyond the {MAX_POSITION:g} m "
                 f"of a motion stage's stroke: if the positions are not in metres, scale them "
                 f"(--scale displacement=0.001 for mm, 1e-6 for um)", 3)
    t = columns.get("time")
    if t is not None and t.size > 1:
        with np.errstate(invalid="ignore"):  # one array of the steps, sorted in place
            steps = np.diff(t)
            step = float(np.median(np.abs(steps, out=steps), overwrite_input=True))
        if 0.0 < step < MIN_TIME_STEP:
            warn(f"{where}: time steps of {step:.3g} s ({1 / step:.3g} Hz sampling): if the "
                 f"time is not in seconds, scale it (--scale time=86400 for days)", 3)


__all__ = ["MAX_POSITION", "MIN_TIME_STEP", "SIZED_UNREAD_BYTES", "VALUE_BYTES", "RecordError",
           "check_unread", "is_mat_file", "parse_columns", "parse_scale", "read_record",
           "record_columns", "record_samples"]
