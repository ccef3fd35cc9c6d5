"""Calling a third-party reader so that nothing it does escapes as a crash or as noise.

Readers throw anything on bad input: ``KeyError``, ``IndexError``,
``UnicodeDecodeError``, ``struct.error``, even ``SystemExit`` (meshio exits
the process on some files).  ``guarded_read`` catches every exception but
``KeyboardInterrupt`` (and ``GeneratorExit``) at the call, keeps the reader's
prints, warnings and log records out of our stdout/stderr, and turns the
failure into an :class:`UnreadableFileError` whose message says in words what
is wrong and what to do; the library's own text goes into ``details`` only.
"""

from __future__ import annotations

import contextlib
import io
import json
import logging
import struct
import warnings
import zipfile
import zlib
from collections.abc import Callable
from typing import TypeVar

from ..errors import InputTooLargeError, ServiceError, UnreadableFileError

__all__ = ["guarded_read", "explain", "is_number"]

T = TypeVar("T")


def explain(exc: BaseException) -> str:
    """What a reader's exception says about the file, in words a person can act on."""
    if isinstance(exc, UnicodeDecodeError):
        return "it holds bytes that are not text where the format expects text (a binary file with this extension?)"
    if isinstance(exc, json.JSONDecodeError):
        return f"its JSON is malformed at line {exc.lineno}, column {exc.colno}"
    if isinstance(exc, (EOFError, struct.error)):
        return "it ends before the data its header announces (a truncated download or copy?)"
    if isinstance(exc, (zipfile.BadZipFile, zlib.error)):
        return "its zip package or compressed data is corrupt"
    if isinstance(exc, KeyError):
        return (
            f"an entry the format requires is missing ({exc.args[0]!r:.60})"
            if exc.args
            else "an entry the format requires is missing"
        )
    if isinstance(exc, IndexError):
        return "an element refers to another one that does not exist (an index past the end)"
    if isinstance(exc, RecursionError):
        return "its structure nests too deeply"
    if isinstance(exc, SystemExit):
        return "the reader gave up on its content"
    if isinstance(exc, (ValueError, TypeError, AttributeError, AssertionError)):
        return "its content does not follow the format (a value of the wrong kind or count)"
    return "its content does not follow the format"


def guarded_read(fn: Callable[[], T], fmt: str) -> T:
    """``fn()``, silenced, with every failure but an interrupt turned into an ``UnreadableFileError``."""
    sink = io.StringIO()
    previous = logging.root.manager.disable
    try:
        logging.disable(logging.CRITICAL)
        with contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return fn()
    except (KeyboardInterrupt, GeneratorExit):
        raise
    except ServiceError:
        raise
    except MemoryError as exc:
        raise InputTooLargeError(
            f"the {fmt.upper()} file is too large to read in the memory available; send a smaller or decimated mesh", format=fmt
        ) from exc
    except BaseException as exc:
        raise UnreadableFileError(
            f"the {fmt.upper()} file could not be read: {explain(exc)}; check that it is a complete {fmt.upper()} "
            "file, or re-export it from the program that made it",
            format=fmt,
            reader_error=f"{type(exc).__name__}: {_short(exc)}",
        ) from None
    finally:
        logging.disable(previous)


def _short(exc: BaseException) -> str:
    text = str(exc).strip()
    return (text.splitlines()[0] if text else "")[:200]


def is_number(token: str | bytes) -> bool:
    """Whether a token of a text file reads as a number (Python's ``float``, as the readers parse it)."""
    try:
        float(token)
    except ValueError:
        return False
    return True
