"""Where batch rows go: JSONL, CSV or Parquet, chosen by the output's extension.

JSONL and CSV rows are written as their task completes and flushed after each
task (one file, or a few small ones), so an interrupted run keeps every
finished row and ``--resume`` carries on.  A line cut short by a crash is
removed before appending (its file is analysed again).

Parquet cannot grow row by row: rows are written in row groups to
``<out>.partial`` and that file replaces ``<out>`` when the run ends (also on
Ctrl-C or an error).  On ``--resume`` the existing rows are copied first.  Only
a hard kill loses the rows of the current run; the previous output stays whole.

Rows come in completion order, not input order; each carries its input's name.

Rows are rendered where they are computed (:func:`render`, on the worker):
the JSON line or CSV line as text, the Parquet row as a tuple of values.  The
client then only appends what comes back (``write_rendered``), so its work per
file stays a few microseconds however many workers feed it.
"""

from __future__ import annotations

import csv
import io
import json
import os
from collections.abc import Iterator
from typing import IO, Any, Protocol

from ..errors import InvalidParameterError
from .extras import require
from .rows import COLUMNS, FLOAT_COLUMNS, Row, flat_row, row_name

__all__ = ["OUTPUT_FORMATS", "Sink", "done_names", "open_sink", "render"]

OUTPUT_FORMATS = {".jsonl": "jsonl", ".ndjson": "jsonl", ".csv": "csv", ".parquet": "parquet"}
PARQUET_ROW_GROUP = 4096  # rows per Parquet row group: ~1 MB of columns, few enough groups to read fast


class Sink(Protocol):
    def write(self, row: Row) -> None: ...
    def write_rendered(self, rendered: Any) -> None:
        """Append a row already rendered by :func:`render` for this sink's format."""

    def flush(self) -> None:
        """Make the rows written so far durable (called after each finished task)."""

    def close(self) -> None: ...


def output_format(path: str) -> str:
    """``jsonl``, ``csv`` or ``parquet`` from the output's extension."""
    ext = os.path.splitext(path)[1].lower()
    try:
        fmt = OUTPUT_FORMATS[ext]
    except KeyError:
        raise InvalidParameterError(
            f"cannot tell the output format of {path!r}; end --out with .jsonl, .csv or .parquet", parameter="out"
        ) from None
    if fmt == "parquet":
        _pyarrow()
    return fmt


def _pyarrow() -> Any:
    return require("pyarrow.parquet", purpose="Parquet output", extra="parquet", parameter="out")


# ---------------------------------------------------------------------------
# resume


def done_names(path: str) -> set[str]:
    """Names of the inputs that already have a row in ``path`` (error rows included).

    A missing or empty output has none.  A trailing line cut short by a crash
    is dropped from the file here, so appending starts on a fresh line.
    """
    if not os.path.exists(path) or os.path.getsize(path) == 0:
        return set()
    fmt = output_format(path)
    if fmt == "parquet":
        table = _pyarrow().parquet.read_table(path, columns=["name"])
        return {str(n) for n in table.column("name").to_pylist()}
    _drop_partial_line(path)
    with open(path, encoding="utf-8", newline="") as fh:
        if fmt == "csv":
            return _csv_names(fh, path)
        return set(_jsonl_names(fh))


def _drop_partial_line(path: str) -> None:
    with open(path, "rb+") as fh:
        fh.seek(0, os.SEEK_END)
        end = fh.tell()
        fh.seek(max(0, end - 1))
        if fh.read(1) == b"\n":
            return
        # scan back to the last newline; the tail after it is an unfinished row
        pos = end
        while pos > 0:
            step = min(1 << 16, pos)
            fh.seek(pos - step)
            chunk = fh.read(step)
            idx = chunk.rfind(b"\n")
            if idx >= 0:
                fh.truncate(pos - step + idx + 1)
                return
            pos -= step
        fh.truncate(0)


def _jsonl_names(fh: IO[str]) -> Iterator[str]:
    for lineno, line in enumerate(fh, 1):
        if not line.strip():
            continue
        try:
            yield row_name(json.loads(line))
        except (json.JSONDecodeError, KeyError, TypeError) as exc:
            raise InvalidParameterError(
                f"line {lineno} of --out is not a batch result line ({exc}); give a new --out or drop --resume",
                parameter="out",
            ) from exc


def _csv_names(fh: IO[str], path: str) -> set[str]:
    reader = csv.DictReader(fh)
    if tuple(reader.fieldnames or ()) != COLUMNS:
        raise InvalidParameterError(
            f"{path!r} does not have the batch CSV columns; give a new --out or drop --resume", parameter="out"
        )
    return {row["name"] for row in reader}


# ---------------------------------------------------------------------------
# writers


def render(row: Row, fmt: str) -> Any:
    """A row as the sink of ``fmt`` writes it: a line of text (JSONL, CSV) or a Parquet row tuple."""
    if fmt == "jsonl":
        # allow_nan=False: the contract never sends NaN, so one here is a bug to see
        return json.dumps(row.as_dict(), allow_nan=False) + "\n"
    flat = flat_row(row)
    if fmt == "csv":
        buf = io.StringIO()
        # csv writes floats with repr(): they read back bit for bit
        csv.writer(buf).writerow([flat[c] for c in COLUMNS])
        return buf.getvalue()
    return tuple(flat[c] for c in COLUMNS)


def open_sink(path: str, append: bool) -> Sink:
    """A writer for ``path``; ``append`` keeps the rows already there."""
    fmt = output_format(path)
    append = append and os.path.exists(path) and os.path.getsize(path) > 0
    if fmt == "jsonl":
        return JsonlSink(path, append)
    if fmt == "csv":
        return CsvSink(path, append)
    return ParquetSink(path, append)


class JsonlSink:
    def __init__(self, path: str, append: bool) -> None:
        self._fh = open(path, "a" if append else "w", encoding="utf-8")  # noqa: SIM115  closed by close()

    def write(self, row: Row) -> None:
        self._fh.write(render(row, "jsonl"))

    def write_rendered(self, rendered: Any) -> None:
        self._fh.write(rendered)

    def flush(self) -> None:
        self._fh.flush()

    def close(self) -> None:
        self._fh.close()


class CsvSink:
    def __init__(self, path: str, append: bool) -> None:
        self._fh = open(path, "a" if append else "w", encoding="utf-8", newline="")  # noqa: SIM115
        self._writer = csv.DictWriter(self._fh, fieldnames=COLUMNS)
        if not append:
            self._writer.writeheader()

    def write(self, row: Row) -> None:
        self._fh.write(render(row, "csv"))

    def write_rendered(self, rendered: Any) -> None:
        self._fh.write(rendered)

    def flush(self) -> None:
        self._fh.flush()

    def close(self) -> None:
        self._fh.close()


def parquet_schema() -> Any:
    pa = _pyarrow()
    return pa.schema([(c, pa.float64() if c in FLOAT_COLUMNS else pa.string()) for c in COLUMNS])


class ParquetSink:
    def __init__(self, path: str, append: bool) -> None:
        pa = _pyarrow()
        self._pa = pa
        self._path = path
        self._partial = path + ".partial"
        self._schema = parquet_schema()
        self._writer = pa.parquet.ParquetWriter(self._partial, self._schema)
        self._buffer: list[tuple[Any, ...]] = []
        if append:
            old = pa.parquet.ParquetFile(path)
            for i in range(old.num_row_groups):
                self._writer.write_table(old.read_row_group(i).select(list(COLUMNS)).cast(self._schema))

    def write(self, row: Row) -> None:
        self.write_rendered(render(row, "parquet"))

    def write_rendered(self, rendered: Any) -> None:
        self._buffer.append(rendered)
        if len(self._buffer) >= PARQUET_ROW_GROUP:
            self._flush()

    def flush(self) -> None:
        """Row groups are written every PARQUET_ROW_GROUP rows; the file is whole only at close()."""

    def _flush(self) -> None:
        if self._buffer:
            columns = list(zip(*self._buffer, strict=True))
            self._writer.write_table(
                self._pa.Table.from_arrays(
                    [self._pa.array(col, type=f.type) for col, f in zip(columns, self._schema, strict=True)], schema=self._schema
                )
            )
            self._buffer = []

    def close(self) -> None:
        self._flush()
        self._writer.close()
        os.replace(self._partial, self._path)
