"""``inertia batch`` as a user meets it: a missing output folder, Ctrl-C, and the principal frame in flat rows.

The box 1 x 2 x 3 has I_x = m (2^2 + 3^2)/12 > I_y > I_z, so its principal axes I1, I2, I3 are the z, y and
x axes (up to sign, right-handed).
"""

from __future__ import annotations

import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from benchmarks.cases import torus, write_stl

ROOT = Path(__file__).resolve().parents[2]
BOX = ROOT / "sample_meshes" / "box.stl"
N_PARTS = 64


def inertia(*args: str, **kwargs: Any) -> subprocess.CompletedProcess[str]:
    run: subprocess.CompletedProcess[str] = subprocess.run(
        [sys.executable, "-m", "inertia", "batch", *args], capture_output=True, text=True, timeout=300, **kwargs
    )
    return run


def test_a_missing_output_folder_is_made(tmp_path: Path) -> None:
    out = tmp_path / "new" / "deeper" / "rows.jsonl"
    done = inertia(str(BOX), "--out", str(out), "--workers", "1", "--no-progress")
    assert done.returncode == 0, done.stderr
    assert json.loads(out.read_text())["mass"] == pytest.approx(6000.0, rel=1e-14)


def test_an_output_folder_that_cannot_be_made_is_one_sentence(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("a file where a folder should be")
    done = inertia(str(BOX), "--out", str(blocker / "rows.jsonl"), "--no-progress")
    assert done.returncode == 6
    assert done.stderr.startswith("error: cannot create the output folder") and "Traceback" not in done.stderr


def test_flat_rows_carry_the_principal_axes_and_quaternion(tmp_path: Path) -> None:
    out = tmp_path / "rows.csv"
    assert inertia(str(BOX), "--out", str(out), "--workers", "1", "--no-progress").returncode == 0
    with out.open(newline="") as fh:
        row = next(csv.DictReader(fh))
    axes = np.array([[float(row[f"axis{i}_{c}"]) for c in "xyz"] for i in (1, 2, 3)])
    assert np.abs(axes) == pytest.approx(np.array([[0, 0, 1], [0, 1, 0], [1, 0, 0]]), abs=1e-15)
    assert np.linalg.det(axes) == pytest.approx(1.0, abs=1e-15)
    w, x, y, z = (float(row[f"q_{c}"]) for c in "wxyz")
    rotation = np.array(
        [  # the quaternion's matrix, written out: it carries principal vectors to the input frame
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )
    assert rotation == pytest.approx(axes.T, abs=1e-15)


@pytest.mark.skipif(os.name != "posix", reason="Ctrl-C is a SIGINT to the foreground process group")
def test_ctrl_c_keeps_the_rows_and_says_how_to_resume(tmp_path: Path) -> None:
    # 64 tori of 1 MB: the batch groups them into several tasks, so rows reach the output well before the
    # end and the interrupt lands mid-run (400 boxes were one task: their rows came at the very end, and the
    # interrupt raced the command's exit)
    folder = tmp_path / "parts"
    folder.mkdir()
    write_stl(folder / "part00.stl", *torus(100, 100))
    for i in range(1, N_PARTS):
        shutil.copy(folder / "part00.stl", folder / f"part{i:02d}.stl")
    out = tmp_path / "rows.jsonl"
    proc = subprocess.Popen(
        [sys.executable, "-m", "inertia", "batch", str(folder), "--out", str(out), "--workers", "2", "--no-progress"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and (not out.exists() or out.stat().st_size == 0):
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGINT)  # what a terminal sends on Ctrl-C
    _, err = proc.communicate(timeout=120)
    if proc.returncode == 0:
        pytest.skip("the run finished before the interrupt arrived")
    assert proc.returncode == 130
    assert "Traceback" not in err
    assert "--resume" in err and str(out) in err
    kept = [json.loads(line) for line in out.read_text().splitlines()]
    assert 0 < len(kept) < N_PARTS
    resumed = inertia(str(folder), "--out", str(out), "--workers", "2", "--no-progress", "--resume")
    assert resumed.returncode == 0, resumed.stderr
    names = [json.loads(line)["source"]["filename"] for line in out.read_text().splitlines()]
    assert len(names) == len(set(names)) == N_PARTS
