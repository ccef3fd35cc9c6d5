"""Where the repository and its sample meshes are (import this, not conftest)."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "sample_meshes"
