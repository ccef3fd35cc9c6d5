"""Quadratic meshes written by Gmsh (tests/data/real/quadratic), against Gmsh's own integration."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from inertia import load_body
from inertia.body import VolumeBody
from inertia.mass import mass_properties
from tests.support.bodies import meshed, volume

QUADRATIC = Path(__file__).resolve().parents[1] / "data" / "real" / "quadratic"
REFERENCE = json.loads((QUADRATIC / "gmsh_reference.json").read_text())


@pytest.mark.parametrize("name", sorted(REFERENCE))
def test_gmsh_quadratic_meshes_match_gmsh_own_integration(name: str) -> None:
    ref = REFERENCE[name]
    props = mass_properties(meshed(load_body(QUADRATIC / name).body), density=1.0)
    tensor = np.array(ref["inertia_unit_density"])
    assert props.mass == pytest.approx(ref["volume"], rel=1e-12)
    np.testing.assert_allclose(props.center_of_mass, ref["center"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(props.inertia.matrix, tensor, rtol=0, atol=1e-12 * np.abs(tensor).max())


def test_quadratic_sphere_is_not_flattened_to_its_corners() -> None:
    body = load_body(QUADRATIC / "sphere_tetra10.msh").body
    assert isinstance(body, VolumeBody) and body.cells[0].type == "tetra10"
    curved = mass_properties(body, density=1.0).mass
    corners = mass_properties(VolumeBody(body.points, body.cells[0].nodes[:, :4]), density=1.0).mass
    ball = 4 / 3 * np.pi
    # a coarse mesh: its corners' polyhedron is 23 % short of the ball, the curved cells under 1 %
    assert abs(curved - ball) / ball < 0.01 < 0.2 < abs(corners - ball) / ball


@pytest.mark.parametrize("name", sorted(REFERENCE))
def test_gmsh_meshes_agree_with_vtk_shape_functions(name: str) -> None:
    volref = pytest.importorskip("tests.load.volref")
    from inertia.body import CellBlock

    body = volume(load_body(QUADRATIC / name).body)
    block = body.cells[0]
    some = block.nodes[:: max(1, len(block.nodes) // 20)]  # about 20 cells: the reference is slow
    m0 = sum(volref.reference_integrals(block.type, body.points[c])[0] for c in some)
    subset = VolumeBody(body.points, np.empty((0, 4), np.int64), cells=(CellBlock(block.type, some),))
    assert mass_properties(subset, density=1.0).mass == pytest.approx(m0, rel=1e-13)
