"""Regenerate the sample meshes and the table of their exact values.

    python -m sample_meshes.generate

Every expected value in README.md here comes from a closed formula or from
exact rational integration (``fractions.Fraction``) of the vertices as
written, never from the service itself.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from benchmarks.cases import box, icosahedron, l_bracket, prism, write_obj, write_stl
from benchmarks.exact import exact_solid

HERE = Path(__file__).resolve().parent


def write_two_density_vtu(path: Path) -> dict[str, float]:
    """A 2x1x1 box of tetrahedra, density 1000 for x < 1 and 8000 for x > 1."""
    import meshio

    pts = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1, 2)], dtype=float)
    idx = {tuple(p): i for i, p in enumerate(pts.tolist())}
    hex_split = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]
    tets, rho = [], []
    for x0, density in ((0, 1000.0), (1, 8000.0)):
        corners = [(x0, 0, 0), (x0 + 1, 0, 0), (x0 + 1, 1, 0), (x0, 1, 0), (x0, 0, 1), (x0 + 1, 0, 1), (x0 + 1, 1, 1), (x0, 1, 1)]
        hexa = [idx[tuple(float(c) for c in p)] for p in corners]
        for t in hex_split:
            tets.append([hexa[k] for k in t])
            rho.append(density)
    mesh = meshio.Mesh(pts, [("tetra", np.array(tets))], cell_data={"density": [np.array(rho)]})
    mesh.write(path)
    # exact: two unit cubes, masses 1000 and 8000, centres (0.5,.5,.5) and (1.5,.5,.5)
    m1, m2 = 1000.0, 8000.0
    m = m1 + m2
    cx = (m1 * 0.5 + m2 * 1.5) / m
    ixx = m * (1 + 1) / 12
    iyy = izz = m * 2 / 12 + m1 * (0.5 - cx) ** 2 + m2 * (1.5 - cx) ** 2
    return {"mass": m, "com_x": cx, "Ixx": ixx, "Iyy": iyy, "Izz": izz}


def main() -> None:
    rows = []

    def solid(name: str, v: np.ndarray, f: np.ndarray, writer=write_stl, note: str = "") -> None:
        writer(HERE / name, v, f)
        vv = v.astype(np.float32).astype(np.float64) if writer is write_stl else v
        vol, com, tensor = exact_solid(vv, f)
        moments = sorted(np.linalg.eigvalsh(np.array([[float(x) * 1000 for x in r] for r in tensor])))
        rows.append((name, float(vol) * 1000, [float(c) for c in com], moments, note))

    solid("box.stl", *box(1.0, 2.0, 3.0), note="1 x 2 x 3 m; I = m(b²+c²)/12 ...: asymmetric")
    solid("hex_prism.stl", *prism(6, 1.0, 2.0), note="regular hexagonal prism R = 1, h = 2: symmetric (prolate)")
    solid("icosahedron.stl", *icosahedron(1.0), note="edge 1: spherical top, I = m φ² a²/10")
    solid(
        "tetrahedron.stl",
        np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float),
        np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
        note="unit corner tetrahedron",
    )
    solid("l_bracket.stl", *l_bracket(2.0), note="L profile extruded 2 m: asymmetric")
    solid(
        "needle.obj",
        *box(1.0, 1e-3, 1e-3, origin=(-0.5, -5e-4, -5e-4)),
        writer=write_obj,
        note="1 x 1e-3 x 1e-3 m needle (OBJ, float64): prolate symmetric, I1/I3 = 2e-6",
    )
    solid(
        "plate.obj",
        *box(1.0, 1.0, 1e-3, origin=(-0.5, -0.5, -5e-4)),
        writer=write_obj,
        note="1 x 1 x 1e-3 m: oblate symmetric, nearly planar",
    )
    v, f = box(1.0, 2.0, 3.0)
    write_stl(HERE / "inverted_box.stl", v, f[:, [0, 2, 1]])
    rows.append(
        (
            "inverted_box.stl",
            6000.0,
            [0.5, 1.0, 1.5],
            [2500.0, 5000.0, 6500.0],
            "box.stl with every face reversed: same numbers plus a warning",
        )
    )
    write_stl(HERE / "open_box.stl", v, f[:-2])
    rows.append(("open_box.stl", None, None, None, "box without its +x face: error not_watertight (4 open edges)"))
    exact = write_two_density_vtu(HERE / "two_density.vtu")
    rows.append(
        (
            "two_density.vtu",
            exact["mass"],
            [exact["com_x"], 0.5, 0.5],
            sorted([exact["Ixx"], exact["Iyy"], exact["Izz"]]),
            "2 x 1 x 1 m of tetrahedra, cell densities 1000 and 8000 kg/m³ (x < 1, x > 1)",
        )
    )
    # isosceles triatomic (seed notes, example 2b): base atoms m1 at (±a/2, 0, 0), apex m2 at (0, h, 0)
    m1, m2, a, h = 1.0, 16.0, 2.0, 1.0
    atoms = [
        {"mass": m1, "position": [-a / 2, 0.0, 0.0]},
        {"mass": m1, "position": [a / 2, 0.0, 0.0]},
        {"mass": m2, "position": [0.0, h, 0.0]},
    ]
    (HERE / "triatomic.json").write_text(json.dumps({"points": atoms}, indent=1) + "\n")
    mu = 2 * m1 + m2
    i1, i2 = 2 * m1 * m2 * h**2 / mu, m1 * a**2 / 2
    rows.append(
        (
            "triatomic.json",
            mu,
            [0.0, m2 * h / mu, 0.0],
            [i1, i2, i1 + i2],
            "isosceles triatomic point masses m1 = 1, m2 = 16 kg, a = 2, h = 1 m: "
            "I1 = 2 m1 m2 h²/μ, I2 = m1 a²/2, I3 = I1 + I2 (planar)",
        )
    )
    _write_readme(rows)


def _fmt(x: float | None) -> str:
    return "" if x is None else f"{x:.12g}"


def _write_readme(rows: list) -> None:
    lines = [
        "# Sample meshes",
        "",
        "Small bodies with known answers, used by the tests and the README examples.",
        "Regenerate with `python -m sample_meshes.generate`. Values are SI at the default",
        "density 1000 kg/m³ and units m, computed by exact rational integration of the",
        "vertices as written (float32 for binary STL) or from closed formulas; moments",
        "are ascending principal moments about the centre of mass.",
        "",
        "| file | mass (kg) | centre of mass (m) | principal moments (kg m²) | what it is |",
        "|---|---|---|---|---|",
    ]
    for name, mass, com, moments, note in rows:
        com_s = "" if com is None else "(" + ", ".join(_fmt(c) for c in com) + ")"
        mom_s = "" if moments is None else ", ".join(_fmt(m) for m in moments)
        lines.append(f"| `{name}` | {_fmt(mass)} | {com_s} | {mom_s} | {note} |")
    (HERE / "README.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
