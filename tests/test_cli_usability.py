"""The CLI as a new user meets it: negative vectors, --version, readable errors, output units, exit codes.

Expected numbers come from the box's closed form (1 x 2 x 3 m at 1000 kg/m^3:
m = 6000 kg, I = m/12 (b^2 + c^2), ...), converted by hand to the requested units.
"""

from __future__ import annotations

import argparse
import json
import socket
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

import pytest

from inertia.cli import ADVICE_OPTIONS, _parser, as_options, main

ROOT = Path(__file__).resolve().parents[1]
BOX = str(ROOT / "sample_meshes" / "box.stl")


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "inertia", *args], capture_output=True, text=True, cwd=ROOT, timeout=120)


def test_negative_vectors_are_taken_as_written(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["analyze", BOX, "--json", "--omega", "-0.1,2,0", "--reference", "-1,0,0"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["reference_inertia"]["point"] == [-1.0, 0.0, 0.0]
    assert "precession" in doc
    assert main(["analyze", BOX, "--json", "--omega=-0.1,2,0", "--reference=-1,0,0"]) == 0
    same = json.loads(capsys.readouterr().out)
    assert same["reference_inertia"] == doc["reference_inertia"]
    assert same["precession"]["omega_body"] == doc["precession"]["omega_body"]


def test_version_is_the_distributions() -> None:
    out = run("--version")
    assert out.returncode == 0
    assert out.stdout.strip() == f"inertia {version('inertia-service')}"


def test_errors_are_sentences_in_table_mode_and_envelopes_with_json(tmp_path: Path) -> None:
    missing = str(tmp_path / "missing.stl")
    table = run("analyze", missing)
    assert table.returncode == 3
    assert table.stderr.startswith("error: ") and "{" not in table.stderr
    assert table.stderr.rstrip().endswith("(unreadable_file)")
    assert table.stdout == ""
    as_json = run("analyze", missing, "--json")
    assert as_json.returncode == 3
    assert json.loads(as_json.stderr)["error"]["code"] == "unreadable_file"


@pytest.mark.parametrize(
    ("units", "mass", "moment", "length"),
    [
        ("si", "6000 kg", "2500", "m"),
        ("kg-mm", "6000 kg", "2.5e+09", "mm"),  # 2500 kg m^2 = 2500e6 kg mm^2
        ("g-mm", "6000000 g", "2.5e+12", "mm"),  # 2500e6 kg mm^2 = 2500e9 g mm^2
        ("g-cm", "6000000 g", "2.5e+10", "cm"),  # 2500e4 kg cm^2 = 2500e7 g cm^2
    ],
)
def test_table_output_units(units: str, mass: str, moment: str, length: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["analyze", BOX, "--output-units", units]) == 0
    out = capsys.readouterr().out
    rows = {line.split("  ")[1].strip(): line for line in out.splitlines()[1:] if line.startswith("  ") and "  " in line[2:]}
    assert mass in rows["mass"]
    assert f"[ {moment}," in rows["principal moments"] and rows["principal moments"].endswith(f" {length}^2")
    assert rows["centre of mass"].endswith(f" {length}")


def test_motion_lines_carry_units(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["analyze", BOX, "--omega", "0.01,1,0.01"]) == 0
    out = capsys.readouterr().out
    motion = [line for line in out.splitlines() if any(k in line for k in ("momentum", "energy", "period", "flip"))]
    assert motion
    units = {"angular momentum magnitude": "kg m^2/s", "kinetic energy": "J", "period": " s", "flip interval": " s"}
    for line in motion:
        label = next(k for k in units if k in line)
        assert line.rstrip().endswith(units[label]), line


def test_advice_reads_as_the_commands_options_in_table_mode(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # an open box: "... analyse it as a thin surface with model=shell and a thickness" is the API's wording
    faces = Path(BOX).read_bytes()
    count = int.from_bytes(faces[80:84], "little")
    open_box = tmp_path / "open.stl"
    open_box.write_bytes(faces[:80] + (count - 1).to_bytes(4, "little") + faces[84 : 84 + 50 * (count - 1)])
    assert main(["analyze", str(open_box)]) == 4
    table = capsys.readouterr().err
    assert "--model shell" in table and "model=shell" not in table
    assert main(["analyze", str(open_box), "--json"]) == 4
    assert "model=shell" in json.loads(capsys.readouterr().err)["error"]["message"]


def test_every_advised_option_is_an_option_of_analyze() -> None:
    parser = _parser()
    subparsers = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    flags = {s for action in subparsers.choices["analyze"]._actions for s in action.option_strings}
    assert {f"--{name}" for name in ADVICE_OPTIONS} <= flags
    assert as_options("pass units=mm, or format=..., not mass_unit=u") == "pass --units mm, or --format ..., not mass_unit=u"


def test_every_option_has_help() -> None:
    parser = _parser()
    subparsers = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for name, sub in subparsers.choices.items():
        for action in sub._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            assert action.help, f"inertia {name}: {action.option_strings or action.dest} has no help text"


def test_serve_on_a_busy_port_says_so_and_exits_6() -> None:
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen(1)
        port = busy.getsockname()[1]
        out = run("serve", "--port", str(port))
    assert out.returncode == 6
    assert f"port {port}" in out.stderr and "--port" in out.stderr
    assert "Traceback" not in out.stderr
