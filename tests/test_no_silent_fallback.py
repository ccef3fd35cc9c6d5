"""No silent fallback: a densities typo, an implausible shell thickness, a millimetre part read in metres,
and mesh objects or arrays handed to ``analyze`` directly.

Reference values: the 1 x 2 x 3 box (m = rho abc, I1 = m (b^2 + c^2)/12, ...), the two-box assembly's masses
from their volumes, the unit cube's surface area 6.
"""

from __future__ import annotations

import io
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import inertia
from benchmarks.cases import cube, stl_bytes
from inertia import AnalysisOptions, analyze
from inertia.errors import InvalidParameterError

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = ROOT / "sample_meshes"


def obj_two_boxes() -> bytes:
    """An OBJ of two unit cubes in groups 'steel' and 'brass' (2 m apart)."""
    out = io.StringIO()
    base = 0
    for name, dx in (("steel", 0.0), ("brass", 2.0)):
        v, f = cube(1.0, (dx, 0.0, 0.0))
        out.write(f"o {name}\n")
        out.writelines(f"v {x} {y} {z}\n" for x, y, z in v)
        out.writelines(f"f {a + 1 + base} {b + 1 + base} {c + 1 + base}\n" for a, b, c in f)
        base += len(v)
    return out.getvalue().encode()


def test_a_densities_typo_is_an_error_naming_the_parts() -> None:
    data = obj_two_boxes()
    ok = analyze(data, filename="pair.obj", options=AnalysisOptions(densities={"steel": 7850, "brass": 8500}))
    assert ok.props.mass == pytest.approx(7850 + 8500, rel=1e-14)
    with pytest.raises(InvalidParameterError) as err:
        analyze(data, filename="pair.obj", options=AnalysisOptions(densities={"steel": 7850, "bras": 8500}))
    assert err.value.code == "invalid_parameter"
    assert "'bras'" in err.value.message and "'brass'" in err.value.message and "'steel'" in err.value.message


def test_a_shell_thicker_than_the_part_is_refused_with_the_figure() -> None:
    v, f = cube(1.0)
    with pytest.raises(InvalidParameterError) as err:
        analyze(stl_bytes(v, f), filename="cube.stl", options=AnalysisOptions(model="shell", thickness=2.0))
    assert "thickness 2 m" in err.value.message and "1.73" in err.value.message


def test_a_thin_shell_is_quiet_and_a_thickish_one_warned() -> None:
    v, f = cube(1.0)
    thin = analyze(stl_bytes(v, f), filename="cube.stl", options=AnalysisOptions(model="shell", thickness=1e-3))
    assert thin.props.mass == pytest.approx(6 * 1e-3 * 1000, rel=1e-12)  # area 6 m^2 x 1 mm x 1000 kg/m^3
    assert not any("thickness" in w for w in thin.warnings)
    thick = analyze(stl_bytes(v, f), filename="cube.stl", options=AnalysisOptions(model="shell", thickness=0.2))
    assert any("thickness 0.2 m" in w and "12%" in w for w in thick.warnings)


def test_a_millimetre_part_read_in_metres_is_warned_about() -> None:
    v, f = cube(120.0)  # a 120 mm cube written without a unit
    result = analyze(stl_bytes(v, f), filename="part.stl")
    assert any("declares no length unit" in w and "units=mm" in w for w in result.warnings)
    in_mm = analyze(stl_bytes(v, f), filename="part.stl", options=AnalysisOptions(units="mm"))
    assert not any("length unit" in w for w in in_mm.warnings)
    assert in_mm.props.mass == pytest.approx(0.12**3 * 1000, rel=1e-6)  # float32 STL coordinates are exact here
    small = analyze(str(SAMPLES / "box.stl"))
    assert not any("length unit" in w for w in small.warnings)


def test_analyze_takes_vertex_and_face_arrays() -> None:
    v, f = cube(1.0)
    v = v * [1.0, 2.0, 3.0]  # the 1 x 2 x 3 box
    result = analyze((v, f), options=AnalysisOptions(density=1000))
    m = 6000.0
    assert result.props.mass == pytest.approx(m, rel=1e-14)
    # I = m/12 (b^2 + c^2), ... for sides a, b, c = 1, 2, 3
    expected = sorted([m * (4 + 9) / 12, m * (1 + 9) / 12, m * (1 + 4) / 12])
    assert np.asarray(result.frame.moments) == pytest.approx(expected, rel=1e-13)


def test_analyze_takes_a_trimesh_object() -> None:
    trimesh = pytest.importorskip("trimesh")
    box = trimesh.creation.box(extents=(1.0, 2.0, 3.0))
    result = analyze(box, options=AnalysisOptions(units="mm"))
    m = 6e-9 * 1000
    assert result.props.mass == pytest.approx(m, rel=1e-14)
    expected = sorted([m * (4 + 9) / 12 * 1e-6, m * (1 + 9) / 12 * 1e-6, m * (1 + 4) / 12 * 1e-6])
    assert np.asarray(result.frame.moments) == pytest.approx(expected, rel=1e-13)


def test_analyze_refuses_other_objects_with_a_sentence() -> None:
    with pytest.raises(InvalidParameterError, match=r"trimesh\.Trimesh or a \(vertices, faces\)"):
        analyze(42)


def test_public_names_are_never_shadowed_by_submodules() -> None:
    code = (
        "import inertia, types; inertia.analyze('sample_meshes/box.stl'); "
        "import inertia.pipeline, inertia.motion, inertia.cli; "
        "from inertia import classify; assert callable(classify) and not isinstance(classify, types.ModuleType); "
        "bad = [n for n in inertia.__all__ if isinstance(getattr(inertia, n), types.ModuleType)]; "
        "assert not bad, bad; print('ok')"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr


def test_import_inertia_needs_no_service_folder_on_the_path(tmp_path: Path) -> None:
    code = "import sys, inertia; r = inertia.analyze(sys.argv[1]); print(r.props.mass); print('service' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code, str(SAMPLES / "box.stl")], capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    mass, service_loaded = out.stdout.split()
    assert float(mass) == pytest.approx(6000.0, rel=1e-14) and service_loaded == "False"
    assert inertia.__name__ == "inertia"
