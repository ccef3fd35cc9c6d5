"""Exit codes of the command line are chosen by the error's class, so a new subclass inherits its family's."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from inertia import errors as E
from inertia.api import transport
from inertia.cli import EXIT_INTERNAL, exit_code


@pytest.mark.parametrize(
    ("error", "status"),
    [
        (E.InvalidParameterError("x"), 2),
        (E.MotionError("x"), 2),
        (E.UnsupportedFormatError("x"), 3),
        (E.UnreadableFileError("x"), 3),
        (E.ExternalReferenceError("x"), 3),
        (E.EmptyGeometryError("x"), 3),
        (E.InputTooLargeError("x"), 3),
        (E.NotWatertightError("x"), 4),
        (E.ZeroVolumeError("x"), 4),
        (E.InsufficientPrecisionError("x"), 4),
        (E.InvalidInertiaError("x"), 4),
        (transport.ServerBusyError("x"), EXIT_INTERNAL),
    ],
)
def test_exit_code_by_class(error: E.ServiceError, status: int) -> None:
    assert exit_code(error) == status


def test_every_core_error_has_an_exit_code() -> None:
    for name in E.__all__:
        cls = getattr(E, name)
        assert isinstance(exit_code(cls("x")), int)


def test_transport_errors_live_in_the_api_package() -> None:
    for name in ("PayloadTooLargeError", "ComputeTimeoutError", "ServerBusyError", "UnauthorizedError"):
        assert not hasattr(E, name)
        assert issubclass(getattr(transport, name), E.ServiceError)
    assert issubclass(transport.PayloadTooLargeError, E.InputTooLargeError)


def test_an_external_reference_is_a_file_that_cannot_be_read(tmp_path: Path) -> None:
    # a glTF whose buffer is another file: the code is external_reference, a subclass of unreadable_file
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"uri": "missing.bin", "byteLength": 36}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0,
    }
    path = tmp_path / "ext.gltf"
    path.write_text(json.dumps(doc), encoding="utf-8")
    out = subprocess.run(
        [sys.executable, "-m", "inertia", "analyze", "--json", str(path)], capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 3, out.stderr
    assert json.loads(out.stderr)["error"]["code"] == "external_reference"


@pytest.mark.parametrize("failure", [ValueError("No path from world->1!"), SystemExit(1), RecursionError()])
def test_a_readers_own_failure_is_an_unreadable_file_on_the_command_line_too(
    failure: BaseException, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # what a library throws while reading is the file's fault, in the same envelope as over HTTP: never a traceback
    import inertia.load as load
    from inertia.cli import main

    def fail(*args: object, **kwargs: object) -> None:
        raise failure

    monkeypatch.setattr(load, "_load_path", fail)
    monkeypatch.setattr(load, "_load_beside", fail)
    path = tmp_path / "box.stl"
    path.write_bytes(b"solid x\nendsolid x\n")
    assert main(["analyze", str(path), "--json"]) == 3
    error = json.loads(capsys.readouterr().err)["error"]
    assert error["code"] == "unreadable_file"
    assert "could not be read" in error["message"] or "too deeply" in error["message"]


_CRASHING_ANALYSIS = """\
import os, signal, sys
from inertia import cli
cli._analyze = lambda args: os.kill(os.getpid(), signal.{sig})
sys.exit(cli.main(["analyze", "part.stl", "--json"], isolate=True))
"""


@pytest.mark.parametrize(
    ("sig", "words"), [("SIGSEGV", "a file reader crashed on it (SIGSEGV)"), ("SIGKILL", "as it does when memory runs out")]
)
def test_the_command_answers_when_its_analysis_dies_by_a_signal(sig: str, words: str) -> None:
    # a native reader's crash (or the kernel's OOM killer) ends the forked child, not the command
    done = subprocess.run([sys.executable, "-c", _CRASHING_ANALYSIS.format(sig=sig)], capture_output=True, text=True)
    assert done.returncode == 3, done.stderr
    error = json.loads(done.stderr)["error"]
    assert error["code"] == "unreadable_file" and words in error["message"] and "'part.stl'" in error["message"]


def test_a_file_that_crashes_a_native_reader_gets_an_error_from_the_command(tmp_path: Path) -> None:
    # a STEP style usage pointing at an entity of another type makes OpenCASCADE's STEP transfer (OCP 8.0)
    # write through a bad pointer: the command died with SIGSEGV and printed nothing
    pytest.importorskip("OCP")
    source = Path(__file__).parent / "data" / "real" / "step" / "red_cube_blue_cylinder.step"
    bad = tmp_path / "styled.step"
    bad.write_bytes(source.read_bytes().replace(b"SURFACE_STYLE_USAGE( .BOTH., #134 )", b"SURFACE_STYLE_USAGE( .BOTH., #2 )"))
    done = subprocess.run([sys.executable, "-m", "inertia", "analyze", str(bad)], capture_output=True, text=True)
    assert done.returncode == 3 and "(unreadable_file)" in done.stderr, done.stderr


_SLOW_ANALYSIS = """\
import os, sys, time
from inertia import cli
def slow(args):
    open(sys.argv[1], "w").write(str(os.getpid()))
    time.sleep(30)
    return 0
cli._analyze = slow
sys.exit(cli.main(["analyze", "part.stl"], isolate=True))
"""


def test_a_request_to_stop_the_command_stops_its_analysis_too(tmp_path: Path) -> None:
    import signal
    import time

    marker = tmp_path / "child.pid"
    command = subprocess.Popen([sys.executable, "-c", _SLOW_ANALYSIS, str(marker)], stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 20
    while not marker.exists() or not marker.read_text():
        assert time.monotonic() < deadline and command.poll() is None
        time.sleep(0.05)
    child = int(marker.read_text())
    command.send_signal(signal.SIGTERM)
    assert command.wait(timeout=10) == 128 + signal.SIGTERM
    with pytest.raises(ProcessLookupError):  # the forked analysis is gone with it (reaped by the command)
        os.kill(child, 0)


def test_a_reader_failure_the_command_reports_prints_the_envelope_alone(tmp_path: Path) -> None:
    # the catch-all logs the reader's exception with its traceback; with no logging configured, Python's
    # last-resort handler printed it on stderr before the JSON envelope
    bad = tmp_path / "odd.gltf"
    bad.write_text('{"asset": {"version": "2.0"}, "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}], "accessors": 7}')
    done = subprocess.run([sys.executable, "-m", "inertia", "analyze", str(bad), "--json"], capture_output=True, text=True)
    assert done.returncode == 3
    assert json.loads(done.stderr)["error"]["code"] == "unreadable_file"  # the envelope and nothing else
