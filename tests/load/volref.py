"""Independent references for volume cells: VTK's own shape functions, other Gauss rules.

A cell's map is evaluated with VTK's ``InterpolateFunctions`` (VTK's own node
order and element definitions, not ours); its Jacobian by central differences
with a step of 1/4, exact for maps of degree <= 2 in each variable (every cell
here); and the integrals by Gauss-Legendre rules of 8 points per variable, with
Duffy's collapse written into the integrand (no Gauss-Jacobi rule, unlike the
code under test), so the rules are exact to degree 15 per variable, beyond what
any of these integrands needs.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
import pytest

vtk = pytest.importorskip("vtk")

VTK_CELLS = {
    "tetra": "vtkTetra",
    "tetra10": "vtkQuadraticTetra",
    "hexahedron": "vtkHexahedron",
    "hexahedron20": "vtkQuadraticHexahedron",
    "hexahedron27": "vtkTriQuadraticHexahedron",
    "wedge": "vtkWedge",
    "wedge15": "vtkQuadraticWedge",
    "wedge18": "vtkBiQuadraticQuadraticWedge",
    "pyramid": "vtkPyramid",
    "pyramid13": "vtkQuadraticPyramid",
    "voxel": "vtkVoxel",
}
VTK_TYPE_IDS = {
    "tetra": 10,
    "voxel": 11,
    "hexahedron": 12,
    "wedge": 13,
    "pyramid": 14,
    "tetra10": 24,
    "hexahedron20": 25,
    "wedge15": 26,
    "pyramid13": 27,
    "hexahedron27": 29,
    "wedge18": 32,
}


def vtk_cell(name: str) -> Any:
    return getattr(vtk, VTK_CELLS[name])()


def parametric_nodes(name: str) -> np.ndarray:
    """VTK's parametric coordinates of the cell's nodes."""
    cell = vtk_cell(name)
    n = cell.GetNumberOfPoints()
    pc = cell.GetParametricCoords()
    return np.array([pc[i] for i in range(3 * n)]).reshape(n, 3)


def vtk_shape(name: str, xi: np.ndarray) -> np.ndarray:
    cell = vtk_cell(name)
    n = cell.GetNumberOfPoints()
    out = np.empty((len(xi), n))
    w = [0.0] * n
    for q, p in enumerate(xi):
        cell.InterpolateFunctions([float(v) for v in p], w)
        out[q] = w
    return out


def _legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1), 0.5 * w


def _reference_points(name: str, n: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Parametric points and weights (collapse Jacobian included) of a Legendre-only rule."""
    x, w = _legendre(n)
    pts, wts = [], []
    for (a, wa), (b, wb), (c, wc) in itertools.product(zip(x, w), zip(x, w), zip(x, w)):
        if name.startswith("tetra"):
            pts.append((a, b * (1 - a), c * (1 - a) * (1 - b)))
            wts.append(wa * wb * wc * (1 - a) ** 2 * (1 - b))
        elif name.startswith("wedge"):
            pts.append((a, b * (1 - a), c))
            wts.append(wa * wb * wc * (1 - a))
        else:  # hexahedra, voxels and VTK's pyramids live on the unit cube
            pts.append((a, b, c))
            wts.append(wa * wb * wc)
    return np.array(pts), np.array(wts)


def reference_integrals(name: str, nodes: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """int dV, int x dV, int x x^T dV of one cell with node coordinates ``nodes`` (n, 3), via VTK."""
    xi, w = _reference_points(name)
    h = 0.25
    x = vtk_shape(name, xi) @ nodes
    jac = np.empty((len(xi), 3, 3))
    for d in range(3):
        step = np.zeros(3)
        step[d] = h
        jac[:, d, :] = (vtk_shape(name, xi + step) @ nodes - vtk_shape(name, xi - step) @ nodes) / (2 * h)
    det = np.linalg.det(jac)
    dv = np.abs(det) * w if np.all(det >= 0) or np.all(det <= 0) else det * w * np.sign(det @ w)
    return float(dv.sum()), (dv[:, None] * x).sum(axis=0), np.einsum("q,qi,qj->ij", dv, x, x)


def inertia_about_centre(m0: float, m1: np.ndarray, m2: np.ndarray, density: float = 1.0) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre and inertia tensor about the centre from the raw integrals (Landau & Lifshitz eq. 32.2)."""
    c = m1 / m0
    cov = m2 - m0 * np.outer(c, c)
    tensor = np.trace(cov) * np.eye(3) - cov
    return m0 * density, c, tensor * density
