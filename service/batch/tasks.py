"""The work of one batch task, run on a Dask worker (or anywhere): read, analyse, report.

A task is a small group of :class:`~service.batch.sources.Source` (one file,
or several small ones to amortise the per-task overhead).  The worker reads
each file itself (path, URL or zip member), analyses it with exactly the
``AnalysisOptions`` of the run, and makes one typed row per file (``rows.Row``:
the result's document, or an error row).  A file that fails gives an error
row; nothing a file does stops the group.
Only the rows travel back, so a worker holds at most one group's files;
:func:`render_sources` sends them rendered for the output (a JSON or CSV line
of text, or a Parquet row tuple), the most compact form the client can
append without further work.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

from ..errors import ServiceError, UnreadableFileError
from ..pipeline import AnalysisOptions, analyze
from ..sections import AnalysisDocument
from .rows import Row, error_row
from .sinks import render
from .sources import Source, ZipCache, read_source
from .workers import relax_frozen_heap_thresholds

__all__ = ["InternalError", "analyze_row", "analyze_rows", "analyze_source", "analyze_sources", "render_sources"]


class InternalError(ServiceError):
    """Something the service cannot explain went wrong with one file."""

    code = "internal_error"


def analyze_row(source: Source, options: AnalysisOptions, zips: ZipCache | None = None) -> Row:
    """The row of one input: its analysis result or its error."""
    try:
        if source.member is None and source.name.lower().endswith(".zip"):
            raise UnreadableFileError(f"{source.name!r} is not a readable zip archive", filename=source.name)
        if source.member is None and "://" not in source.location and os.path.isfile(source.location):
            # a file on this machine's disk: read by path, with the files it names beside it (a .gltf's .bin),
            # as ``inertia analyze`` reads it
            return analyze(source.location, filename=source.name, options=options).document()
        data = read_source(source, zips)
        return analyze(data, filename=source.name, options=options).document()
    except ServiceError as exc:
        return error_row(source.name, exc)
    except Exception as exc:
        err = InternalError(f"unexpected {type(exc).__name__} while analysing this file: {exc}; please report it")
        return error_row(source.name, err)


def analyze_rows(sources: Sequence[Source], options: AnalysisOptions) -> list[Row]:
    """The rows of a group of inputs, in the group's order."""
    relax_frozen_heap_thresholds()  # on a Dask worker: see ``workers``
    zips = ZipCache()
    try:
        return [analyze_row(src, options, zips) for src in sources]
    finally:
        zips.close()


def analyze_source(source: Source, options: AnalysisOptions, zips: ZipCache | None = None) -> dict[str, Any]:
    """The JSON line of one input: its analysis result or its error."""
    return analyze_row(source, options, zips).as_dict()


def analyze_sources(sources: Sequence[Source], options: AnalysisOptions) -> list[dict[str, Any]]:
    """The JSON lines of a group of inputs, in the group's order."""
    return [row.as_dict() for row in analyze_rows(sources, options)]


def render_sources(sources: Sequence[Source], options: AnalysisOptions, fmt: str) -> list[tuple[Any, bool]]:
    """(the row rendered for an output of format ``fmt``, whether it is an error row) for each input."""
    return [(render(row, fmt), not isinstance(row, AnalysisDocument)) for row in analyze_rows(sources, options)]
