"""One reader for every tabular input: CSV files as engineers have them, arrays and DataFrames.

Every CSV the package reads (measured records, references, measured plants)
goes through :func:`read_columns` and :func:`read_header`, built on
:func:`pandas.read_csv`.  They accept what spreadsheets and measurement
software write:

- UTF-8 with or without a byte-order mark (UTF-16 with a BOM too), LF or CRLF
  line ends;
- comma, semicolon or tab as separator, spaces after it; with semicolons, a
  decimal comma (``1,5;2,25``) where the data rows use one;
- column names matched case-insensitively with surrounding spaces trimmed
  (``" Time "`` is ``time``); extra columns are ignored.

Errors are :class:`CSVError` (a ``ValueError``) with one line naming the
source: a missing file, an empty file, a header without the expected columns
(the message names them), a row with too many fields, a cell that is not a
number (by line and column).  Where a path is accepted, a numpy array (its
columns in the order asked for) or a pandas DataFrame (columns by name, matched
as in a CSV header) is accepted too.  Floats are parsed by pandas' C parser
straight into float64 columns, so a million-row file costs its numbers, not
Python objects.
"""

from __future__ import annotations

import codecs
import csv
import os
import re
import sys
import typing
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from motionhyst.core.budget import check_memory, format_size
from motionhyst.io.inputs import CSV_EXPANSION, input_problem

if typing.TYPE_CHECKING:  # pandas loads when a file is parsed: a file refused before it
    import pandas as pd  # (a folder, a device, an empty or binary file) does not wait for it

Source = typing.Union[str, os.PathLike, np.ndarray, "pd.DataFrame", Mapping]
"""What the readers accept: a CSV path, a 2-D array or a DataFrame (or a mapping of columns)."""

_SEPARATORS = (",", ";", "\t")
_SNIFF_BYTES = 64 * 1024

_MAX_EXTRA_FIELDS = 1000   # a data row of more fields than its header's and these is refused
_MAX_FIELD_BYTES = 64      # ... when its line is longer than this per field (checked unread)
_CHUNK_BYTES = 1 << 22
_FIRST_ROWS = 2000         # data rows checked without pandas (a units row, a short row...)
_CHUNK_ROWS = 1 << 17
"""Rows pandas' C parser reads at a time (:func:`_read_csv`): read whole, its default
(``low_memory``) reserved 23 times a file's size of address space, most of it never touched
(459 MB for 1e6 rows of two columns, a file of 21 MB; resident 63 MB), so that a run sized
by its estimate could not be held to it by an address-space limit; in chunks of this many
rows, concatenated, 42 MB (resident 66 MB), in about the same CPU time."""
_NUMBER = r"[+-]?(?:\d+[.{0}]?\d*|[.{0}]\d+)(?:[eE][+-]?\d+)?"
_UNDECIDED = ("nan", "na", "inf", "null", "none", "#", "ind", "true", "false")  # words pandas
# may read as NaN, an infinity or a column of booleans: pandas decides


class CSVError(ValueError):
    """A tabular input that cannot be used: one line naming the source and the problem.

    Examples
    --------
    >>> import numpy as np
    >>> from motionhyst.io.csvdata import CSVError, read_columns
    >>> try:
    ...     read_columns(np.zeros((3, 1)), ("time", "position"))
    ... except CSVError as err:
    ...     print("CSVError:", err)                         # doctest: +ELLIPSIS
    CSVError: ...
    """


def normalize_name(name: Any) -> str:
    """A column name as matched: trimmed, lower case, byte-order mark and quotes removed.

    Parameters
    ----------
    name : object
        A column name as read.

    Examples
    --------
    >>> normalize_name('\\ufeff Time ')
    'time'
    """
    return str(name).replace("\ufeff", "").strip().strip('"').strip().lower()


def describe(source: Source) -> str:
    """How messages name a source: its path, or the kind of in-memory table.

    Parameters
    ----------
    source : str, Path, ndarray or DataFrame
        A record's source.

    Examples
    --------
    >>> describe("data/rec.csv")
    'data/rec.csv'
    >>> import numpy as np
    >>> describe(np.zeros((3, 2)))
    'the array'
    """
    if _is_frame(source):
        return "the DataFrame"
    if isinstance(source, np.ndarray):
        return "the array"
    if isinstance(source, Mapping):
        return "the table"
    return str(source)


def _is_frame(source: Source) -> bool:
    """Whether `source` is a pandas DataFrame (there is none unless pandas is loaded)."""
    pd = sys.modules.get("pandas")
    return pd is not None and isinstance(source, pd.DataFrame)


def _is_path(source: Source) -> bool:
    return isinstance(source, str | os.PathLike)


class _Dialect(typing.NamedTuple):
    encoding: str
    sep: str
    decimal: str
    header_line: int  # 1-based line of the header (blank lines before it are skipped)


def _dialect(path: Path) -> _Dialect:
    """Encoding, separator, decimal mark and header line of a CSV file, from its first bytes.
    Only the file's type is checked here (a folder, a device): what reading it takes is
    sized from its rows (:func:`reading_bytes`), not from its bytes."""
    why = input_problem(path, 0.0)
    if why:
        raise CSVError(f"cannot read {path}: {why}")
    try:
        with path.open("rb") as fh:
            head = fh.read(_SNIFF_BYTES)
    except IsADirectoryError:
        raise CSVError(f"cannot read {path}: it is a folder") from None
    except OSError as exc:
        raise CSVError(f"cannot read {path}: {exc.strerror}") from None
    if head.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        encoding = "utf-16"
    else:
        encoding = "utf-8-sig"
    text = head.decode(encoding, errors="replace")
    physical = text.split("\n")
    first = next((i for i, ln in enumerate(physical) if ln.strip()), None)
    if first is None:
        raise CSVError(f"{path}: empty file: no header, no data rows")
    header = physical[first]
    counts = {s: header.count(s) for s in _SEPARATORS}
    sep = max(_SEPARATORS, key=lambda s: counts[s])
    if counts[sep] == 0:
        sep = ","
    data = [ln for ln in physical[first + 1:] if ln.strip()]
    decimal = ("," if sep == ";" and any("," in ln for ln in data)
               and not any("." in ln for ln in data) else ".")
    return _Dialect(encoding, sep, decimal, first + 1)


def _parser_message(text: str, sep: str) -> str:
    """pandas' tokenizer error as one line: ``inconsistent lengths: line N has F fields ...``."""
    m = re.search(r"Expected (\d+) fields in line (\d+), saw (\d+)", text)
    if m:
        want, line, saw = m.groups()
        return f"inconsistent lengths: line {line} has {saw} fields, the line before {want}"
    return "cannot parse: " + " ".join(text.split())


def _read_csv(path: Path, d: _Dialect, empty: str = "empty file: no header, no data rows",
              **options) -> pd.DataFrame:
    """The file through pandas' C parser, :data:`_CHUNK_ROWS` rows at a time, with one-line
    errors naming it."""
    import pandas as pd

    try:
        with pd.read_csv(path, sep=d.sep, skipinitialspace=True, encoding=d.encoding,
                         encoding_errors="replace", decimal=d.decimal, engine="c",
                         skip_blank_lines=True, chunksize=_CHUNK_ROWS, **options) as reader:
            chunks = list(reader)
        if not chunks:
            raise pd.errors.EmptyDataError
        return chunks[0] if len(chunks) == 1 else pd.concat(chunks, ignore_index=True)
    except pd.errors.EmptyDataError:
        raise CSVError(f"{path}: {empty}") from None
    except pd.errors.ParserError as exc:
        raise CSVError(f"{path}: {_parser_message(str(exc), d.sep)}") from None
    except (OSError, UnicodeError) as exc:
        raise CSVError(f"cannot read {path}: {getattr(exc, 'strerror', None) or exc}") from None


def _file_header(path: Path, d: _Dialect) -> list[str]:
    """Normalised names of the header line (an unnamed column is ``""``); a name given twice
    is a CSVError (pandas would rename the second ``name.1`` and one of them be read).  Read
    without pandas, as its parser reads it (quotes, spaces after the separator): a file
    whose header is refused does not wait for pandas to load."""
    names = _raw_header(path, d)
    _check_unique(names, str(path))
    return names


def _raw_header(path: Path, d: _Dialect) -> list[str]:
    """Normalised names of the header line as written, repeated names kept."""
    try:
        with path.open(encoding=d.encoding, errors="replace", newline="") as fh:
            for number, line in enumerate(fh, 1):
                if number == d.header_line:
                    fields = next(csv.reader([line], delimiter=d.sep, skipinitialspace=True),
                                  [])
                    return [normalize_name(c) for c in fields]
    except csv.Error as exc:  # a NUL byte in the header: not a text table
        raise CSVError(f"{path}: cannot parse the header line: {exc}") from None
    except OSError as exc:
        raise CSVError(f"cannot read {path}: {exc.strerror}") from None
    return []


def read_header(source: Source) -> list[str]:
    """The column names of a CSV file or DataFrame, normalised (see :func:`normalize_name`).

    Parameters
    ----------
    source : str, Path or DataFrame
        CSV file with a header row, or a DataFrame.

    Returns
    -------
    list of str
        Column names, trimmed and in lower case, in file order (an unnamed
        column, as after a trailing separator, is ``""``).

    Raises
    ------
    CSVError
        One line naming the file: unreadable, empty, or a name given twice.

    Examples
    --------
    >>> import pandas as pd
    >>> read_header(pd.DataFrame({" Time": [0.0], "Position ": [1.0]}))
    ['time', 'position']
    """
    if isinstance(source, np.ndarray):
        raise CSVError("an array has no column names; give a CSV file or a DataFrame")
    if _is_frame(source):
        names = [normalize_name(c) for c in source.columns]
    elif isinstance(source, Mapping):
        names = [normalize_name(c) for c in source]
    else:
        path = Path(source)
        names = _file_header(path, _dialect(path))
    _check_unique(names, describe(source))
    return names


def _check_unique(names: Sequence[str], where: str) -> None:
    seen = set()
    for n in names:
        if n and n in seen:
            raise CSVError(f"{where}: column {n!r} appears twice in the header "
                           f"(names are matched ignoring case and spaces)")
        seen.add(n)


def _line_of_row(path: Path, row: int) -> int | None:
    """File line (1-based) of data row `row` (0-based), blank lines skipped as pandas does."""
    d = _dialect(path)
    with path.open(encoding=d.encoding, errors="replace", newline="") as fh:
        seen = -1  # the header is row -1
        for number, line in enumerate(fh, start=1):
            if number < d.header_line or not line.strip():
                continue
            if seen == row:
                return number
            seen += 1
    return None


def _where(source: Source, row: int) -> str:
    """``line N`` of a file for data row `row` (0-based), else ``row N`` (1-based)."""
    if _is_path(source):
        line = _line_of_row(Path(source), row)
        if line is not None:
            return f"line {line}"
    return f"row {row + 1}"


def _check_line_lengths(path: Path, d: _Dialect, width: int) -> None:
    """Refuse a file with a line far longer than a row of `width` fields, before pandas reads
    it: each of its fields would become a column (minutes for a line of 1e7 fields)."""
    if d.encoding == "utf-16":  # two bytes a character; such files are small exports
        return
    limit = (width + _MAX_EXTRA_FIELDS) * _MAX_FIELD_BYTES
    line, start, pos = 1, 0, 0   # the current line's number and its first byte's offset
    with path.open("rb") as fh:
        while chunk := fh.read(_CHUNK_BYTES):
            ends = np.flatnonzero(np.frombuffer(chunk, np.uint8) == 10) + pos
            starts = np.concatenate(([start], ends[:-1] + 1))
            long = np.flatnonzero(ends - starts > limit)
            pos += len(chunk)
            if long.size:
                line, start = line + int(long[0]), int(starts[long[0]])
                break
            if ends.size:
                line, start = line + ends.size, int(ends[-1]) + 1
            if pos - start > limit:
                break
        else:
            return
        fh.seek(start)
        fields, size = 1, 0
        while chunk := fh.read(_CHUNK_BYTES):
            head = chunk.split(b"\n", 1)[0]
            fields += head.count(d.sep.encode())
            size += len(head)
            if len(head) < len(chunk):
                break
    if fields > width:
        raise CSVError(f"{path}: inconsistent lengths: line {line} has {fields} fields, the "
                       f"header {width} (refused unread)")
    raise CSVError(f"{path}: line {line} is {format_size(size)} long: not a row of {width} "
                   f"numbers (refused unread)")


def _check_first_rows(path: Path, d: _Dialect, wanted: list[int], names: Sequence[str],
                      width: int) -> None:
    """Refuse, before pandas loads, the first of the first :data:`_FIRST_ROWS` data rows
    that pandas' reading would refuse for certain (a units row under the header, an empty
    cell, a row short of a wanted column or with more fields than the header), with the
    message its reading gives; a cell that pandas may read as a number or NaN passes (pandas
    decides)."""
    number = re.compile(_NUMBER.format(re.escape(d.decimal)))
    try:
        with path.open(encoding=d.encoding, errors="replace", newline="") as fh:
            rows = 0
            for line_number, line in enumerate(fh, 1):
                if line_number <= d.header_line or not line.strip():
                    continue
                rows += 1
                if rows > _FIRST_ROWS or '"' in line:  # a quoted cell may span lines
                    return
                fields = next(csv.reader([line], delimiter=d.sep, skipinitialspace=True), [])
                cells = [f.strip() for f in fields]
                if len(cells) <= max(wanted) or any(cells[width:]):
                    raise CSVError(f"{path}: inconsistent lengths: line {line_number} has "
                                   f"{len(cells)} fields, the header {width}")
                for i, name in zip(wanted, names, strict=True):
                    if not cells[i]:
                        raise CSVError(f"{path}: an empty cell at line {line_number}, column "
                                       f"{name!r}")
                    if not number.fullmatch(cells[i]) and not any(
                            w in cells[i].lower() for w in _UNDECIDED):
                        raise CSVError(f"{path}: non-numeric value {cells[i]!r} at line "
                                       f"{line_number}, column {name!r}")
    except (csv.Error, OSError):
        return  # pandas reads it and says what is wrong


def _check_has(path: Path, header: list[str], names: tuple[str, ...]) -> None:
    """Refuse a file whose header lacks any of the columns `names`, naming them."""
    missing = [n for n in names if n not in header]
    if missing:
        found = ",".join(header) or "none"
        raise CSVError(f"{path}: missing column(s) {', '.join(missing)}; need a header with "
                       f"{','.join(names)} (found {found})")


def _file_columns(path: Path, names: tuple[str, ...]) -> pd.DataFrame:
    """The columns `names` of a CSV file (floats where they parse), rows checked for length:
    read whole, as a file whose cells are not all plain numbers is (its message found), within
    :data:`~motionhyst.io.inputs.CSV_EXPANSION` times its size."""
    why = input_problem(path, CSV_EXPANSION)
    if why:
        raise CSVError(f"cannot read {path}: {why}")
    d = _dialect(path)
    header = _file_header(path, d)
    _check_unique(header, str(path))
    _check_has(path, header, names)
    width = len(header)
    _check_line_lengths(path, d, width)
    _check_first_rows(path, d, [header.index(n) for n in names], names, width)
    frame = _read_csv(path, d, "no data rows", header=None, skiprows=d.header_line)
    if frame.shape[1] > width:  # more fields than names: allowed only if empty (trailing sep)
        used = frame.iloc[:, width:].notna().to_numpy().any(axis=1)
        if used.any():
            i = int(np.argmax(used))
            fields = int(frame.iloc[i].notna().sum())
            raise CSVError(f"{path}: inconsistent lengths: {_where(path, i)} has {fields} "
                           f"fields, the header {width}")
        frame = frame.iloc[:, :width]
    frame.columns = header[:frame.shape[1]]
    if frame.shape[1] < width and len(frame):  # every row short
        raise CSVError(f"{path}: inconsistent lengths: {_where(path, 0)} has "
                       f"{frame.shape[1]} fields, the header {width}")
    return frame[list(names)]


def _file_array(path: Path, names: tuple[str, ...]) -> NDArray[np.float64] | None:
    """The columns `names` of a CSV file as one float array, filled a chunk of rows at a time
    (:func:`_chunk_rows`) after its rows are sized against the memory budget
    (:func:`reading_bytes`); None where a chunk is not plain numbers (a cell pandas does not
    read as a float, a NaN, a row with more used fields than the header or short of them):
    :func:`_file_columns` then reads it whole and says what is wrong (or keeps a written
    ``nan``)."""
    d = _dialect(path)
    header = _file_header(path, d)
    _check_has(path, header, names)
    width = len(header)
    wanted = [header.index(n) for n in names]
    _check_line_lengths(path, d, width)
    _check_first_rows(path, d, wanted, names, width)
    rows, exact = data_rows(path)
    said = f"{rows} rows" if exact else f"about {rows} rows"
    check_memory(reading_bytes(rows, len(names), width), f"{path} ({said}, not read yet): reading "
                 f"its {len(names)} columns", "give a smaller file")
    import pandas as pd  # once the file's first rows are checked: a refusal does not wait

    capacity = rows if exact else rows + rows // 8 + 1024
    data = np.empty((capacity, len(names)))
    filled = 0
    try:
        with pd.read_csv(path, sep=d.sep, skipinitialspace=True, encoding=d.encoding,
                         encoding_errors="replace", decimal=d.decimal, engine="c",
                         skip_blank_lines=True, chunksize=_chunk_rows(width), header=None,
                         skiprows=d.header_line) as reader:
            for chunk in reader:
                if chunk.shape[1] < width or (chunk.shape[1] > width and bool(
                        chunk.iloc[:, width:].notna().to_numpy().any())):
                    return None
                if not all(pd.api.types.is_float_dtype(t) or pd.api.types.is_integer_dtype(t)
                           for t in chunk.dtypes.iloc[wanted]):
                    return None
                end = filled + len(chunk)
                if end > data.shape[0]:  # more rows than estimated
                    capacity = max(end, data.shape[0] * 3 // 2)
                    check_memory(reading_bytes(capacity, len(names), width), f"{path} (more than "
                                 f"{filled} rows, in reading): reading its {len(names)} "
                                 f"columns", "give a smaller file")
                    data.resize((capacity, len(names)), refcheck=False)
                for j, i in enumerate(wanted):  # a column at a time: no copy of the chunk
                    data[filled:end, j] = chunk.iloc[:, i].to_numpy(dtype=np.float64)
                if np.isnan(data[filled:end]).any():
                    return None
                filled = end
    except pd.errors.EmptyDataError:
        raise CSVError(f"{path}: no data rows") from None
    except pd.errors.ParserError as exc:
        raise CSVError(f"{path}: {_parser_message(str(exc), d.sep)}") from None
    except (OSError, UnicodeError) as exc:
        raise CSVError(f"cannot read {path}: {getattr(exc, 'strerror', None) or exc}") from None
    if filled == 0:
        raise CSVError(f"{path}: no data rows")
    data.resize((filled, len(names)), refcheck=False)  # in place: no copy
    return data


def _bad_cell(frame: pd.DataFrame, names: Sequence[str], source: Source) -> str | None:
    """A message for the first cell that is not a number, or None if all are numbers."""
    import pandas as pd

    where = describe(source)
    for name in names:
        col = frame[name]
        if pd.api.types.is_numeric_dtype(col.dtype):
            continue
        values = pd.to_numeric(col, errors="coerce")
        bad = (values.isna() & col.notna()).to_numpy()
        if bad.any():
            i = int(np.argmax(bad))
            return (f"{where}: non-numeric value {str(col.iloc[i]).strip()!r} at "
                    f"{_where(source, i)}, column {name!r}")
    if not _is_path(source):
        return None  # NaN in memory is the caller's value, checked as non-finite
    blank = frame[list(names)].isna().to_numpy().any(axis=1)
    if not blank.any():
        return None
    # NaN from the file: the text nan (kept), an empty cell or a short row (errors)
    path = Path(source)
    d = _dialect(path)
    width = len(_file_header(path, d))
    raw = _read_csv(path, d, header=None, skiprows=d.header_line, dtype=str,
                    keep_default_na=False, na_values=[])
    raw = raw.iloc[:, :width]
    raw.columns = _file_header(path, d)[:raw.shape[1]]
    empty = (raw[list(names)].apply(lambda c: c.str.strip()) == "").to_numpy()
    rows = np.flatnonzero(empty.any(axis=1))
    if rows.size == 0:
        return None
    i = int(rows[0])
    line = _line_of_row(path, i)
    if line is not None:
        one = _read_csv(path, d, header=None, skiprows=line - 1, nrows=1, dtype=str,
                        keep_default_na=False, na_values=[])
        if one.shape[1] < width:
            return (f"{where}: inconsistent lengths: line {line} has {one.shape[1]} fields, "
                    f"the header {width}")
    name = names[int(np.argmax(empty[i]))]
    return f"{where}: an empty cell at {_where(source, i)}, column {name!r}"


COUNTED_BYTES = 64 << 20
"""CSV files up to this size have their rows counted (:func:`count_rows`, 0.2 s); a larger
one's are estimated from its size and the lengths of lines sampled across it
(:func:`data_rows`), so that a file of gigabytes is sized in milliseconds."""

_PROBES = 64
_PROBE_BYTES = 1 << 14

VALUE_READ_BYTES = 8
"""Memory a value read from a CSV file takes in its array [bytes] (float64): the rows are
parsed :data:`_CHUNK_ROWS` at a time and their wanted columns copied into one array; a row
has one more, the time steps its reader checks."""

CHUNK_VALUE_BYTES = 256
"""Memory of reading a value of a chunk of rows besides the array [bytes]: pandas' parser,
its tokens and its frame of every column of the chunk (:func:`_chunk_rows`: 33.6 MB for a
whole chunk).  Measured, address space above a warmed process: 1e5 and 1e6 rows of 2
columns 29 and 46 MB (:func:`reading_bytes` 36 and 57), of 5 columns 37 and 75 MB (38 and
82)."""


def _chunk_rows(width: int) -> int:
    """Rows read at a time from a file of `width` columns: about 1.3e5 values a chunk."""
    return max(1024, _CHUNK_ROWS // max(width, 1))


def reading_bytes(rows: int, columns: int, width: int | None = None) -> float:
    """Memory :func:`read_columns` takes to read `columns` columns of `rows` rows of a CSV
    file [bytes]: the array, the time steps checked and one chunk's parsing.

    Parameters
    ----------
    rows : int
        The file's data rows.
    columns : int
        The columns read.
    width : int, optional
        The file's columns, all parsed a chunk at a time (default `columns`).

    Returns
    -------
    float

    Examples
    --------
    >>> round(reading_bytes(1_000_000, 5) / 1e6, 1)           # 40 MB of values, one chunk
    81.6
    >>> round(reading_bytes(200, 5) / 1e6, 2)                 # a chunk of 200 rows
    0.27
    """
    width = columns if width is None else width
    return (VALUE_READ_BYTES * float(rows) * (columns + 1)
            + CHUNK_VALUE_BYTES * float(min(rows, _chunk_rows(width))) * width)


def _estimated_rows(path: Path, d: _Dialect) -> int:
    """The data rows of a CSV file from its size over the mean length of the lines found in
    :data:`_PROBES` pieces of :data:`_PROBE_BYTES` spread over it (a record at rest at both
    ends has its longest lines in the middle)."""
    size = path.stat().st_size
    spans = lines = 0
    with path.open("rb") as fh:
        head = fh.read(_PROBE_BYTES)
        ends = np.flatnonzero(np.frombuffer(head, np.uint8) == 10)[:d.header_line]
        start = int(ends[-1]) + 1 if len(ends) == d.header_line else len(head)
        for offset in np.linspace(start, size, _PROBES, endpoint=False).astype(int):
            fh.seek(max(int(offset) - 1, 0))
            piece = np.frombuffer(fh.read(_PROBE_BYTES + 1), np.uint8)
            where = np.flatnonzero(piece == 10)
            if where.size >= 2:
                spans += int(where[-1] - where[0])
                lines += where.size - 1
    if lines == 0:  # lines longer than a piece: one row at most each
        return max(1, (size - start) // _PROBE_BYTES)
    return max(1, round((size - start) * lines / spans))


def data_rows(path: str | os.PathLike) -> tuple[int, bool]:
    """The data rows of a CSV file before it is read, and whether the count is exact: counted
    (:func:`count_rows`) in a file up to :data:`COUNTED_BYTES`, estimated from the lengths of
    lines sampled across a larger one.

    Parameters
    ----------
    path : str or os.PathLike
        A CSV file.

    Returns
    -------
    (int, bool)
        The rows, and True where they were counted.

    Raises
    ------
    CSVError
        The file cannot be read (a folder, a device, an empty file).

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "r.csv"
    ...     _ = path.write_text("time,force\\n" + "".join(f"{i},{i % 7}\\n" for i in range(999)))
    ...     data_rows(path)
    (999, True)
    """
    path = Path(path)
    d = _dialect(path)
    try:
        if path.stat().st_size <= COUNTED_BYTES or d.encoding == "utf-16":
            return count_rows(path), True
        return _estimated_rows(path, d), False
    except OSError as exc:
        raise CSVError(f"cannot read {path}: {exc.strerror}") from None


def count_rows(path: str | os.PathLike) -> int:
    """The data rows of a CSV file, counted without parsing it: its lines after the header
    that hold more than a line end, read 1 MB at a time (0.15 s for 47 MB).

    Parameters
    ----------
    path : str or os.PathLike
        A CSV file (checked as :func:`read_columns` checks it: a folder, a device or an empty
        file are refused).

    Returns
    -------
    int
        The rows (0 for a file of a header alone); a line of spaces alone counts as a row.

    Raises
    ------
    CSVError
        The file cannot be read.

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "r.csv"
    ...     _ = path.write_text("\\ntime,force\\n" + "".join(f"{i / 1000},{i % 7 - 3.5}\\n"
    ...                                                    for i in range(100000)) + "\\n0,1")
    ...     count_rows(path)              # a blank line before the header; the last unended
    100001
    """
    path = Path(path)
    d = _dialect(path)
    blank = 3 if d.encoding == "utf-16" else 1  # a blank line's bytes: a CR (and UTF-16's NULs)
    rows, lines, last, pos = 0, 0, -1, 0  # rows counted, lines ended, the last end, offset
    try:
        with path.open("rb") as fh:
            while chunk := fh.read(1 << 20):
                ends = np.flatnonzero(np.frombuffer(chunk, np.uint8) == 10) + pos
                if ends.size:
                    lengths = np.diff(ends, prepend=last) - 1
                    rows += int(np.count_nonzero(lengths[max(0, d.header_line - lines):]
                                                 > blank))
                    lines += ends.size
                    last = int(ends[-1])
                pos += len(chunk)
    except OSError as exc:
        raise CSVError(f"cannot read {path}: {exc.strerror}") from None
    return rows + (lines >= d.header_line and pos - last - 1 > blank)


def read_columns(source: Source, names: Sequence[str]) -> NDArray[np.float64]:
    """The named columns of a table as a float array of shape ``(rows, len(names))``.

    Parameters
    ----------
    source : str, Path, ndarray, DataFrame or mapping
        A CSV file with a header row (see the module docstring for the
        dialects read), a DataFrame or mapping whose column names are matched
        like a CSV header, or a 2-D array whose columns are `names` in order.
    names : sequence of str
        Columns wanted, lower case (matched ignoring case and surrounding spaces).

    Returns
    -------
    ndarray
        Float64, C-contiguous, one column per name.  Cells ``nan`` or ``inf``
        written as such are kept (callers check finiteness in their own terms).

    Raises
    ------
    CSVError
        One line naming the source: unreadable or empty, no data rows, a
        missing column (the message lists the columns expected and those
        found), a row with more fields than the header, an empty or
        non-numeric cell (by line and column).

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> read_columns(pd.DataFrame({"Time": [0.0, 0.1], "position": [0.0, 1e-3]}),
    ...              ("time", "position"))
    array([[0.   , 0.   ],
           [0.1  , 0.001]])
    >>> read_columns(np.array([[0.0, 1.0], [0.5, 2.0]]), ("time", "position"))[:, 1]
    array([1., 2.])
    """
    names = tuple(names)
    where = describe(source)
    if isinstance(source, np.ndarray):
        data = np.asarray(source)
        if data.ndim != 2 or data.shape[1] != len(names):
            raise CSVError(f"{where}: need shape (rows, {len(names)}) with the columns "
                           f"{','.join(names)}; got shape {data.shape}")
        try:
            data = np.ascontiguousarray(data, dtype=np.float64)
        except (TypeError, ValueError):
            raise CSVError(f"{where}: non-numeric values") from None
        if data.shape[0] == 0:
            raise CSVError(f"{where}: no data rows")
        return data
    if _is_frame(source) or isinstance(source, Mapping):
        import pandas as pd

        frame = source if _is_frame(source) else pd.DataFrame(dict(source))
        frame = frame.rename(columns=normalize_name)
        _check_unique(list(frame.columns), where)
        missing = [n for n in names if n not in frame.columns]
        if missing:
            raise CSVError(f"{where}: missing column(s) {', '.join(missing)}; need the "
                           f"columns {','.join(names)} (found "
                           f"{','.join(map(str, frame.columns)) or 'none'})")
        frame = frame[list(names)]
    else:
        data = _file_array(Path(source), names)
        if data is not None:
            return data
        frame = _file_columns(Path(source), names)
    if len(frame) == 0:
        raise CSVError(f"{where}: no data rows")
    msg = _bad_cell(frame, names, source)
    if msg is not None:
        raise CSVError(msg)
    data = np.empty((len(frame), len(names)))  # filled a column at a time: no copy between
    for j, name in enumerate(names):
        data[:, j] = frame[name].to_numpy(dtype=np.float64)
    return data


__all__ = ["CHUNK_VALUE_BYTES", "COUNTED_BYTES", "VALUE_READ_BYTES", "CSVError", "count_rows",
           "data_rows", "describe", "normalize_name", "read_columns", "read_header",
           "reading_bytes"]
