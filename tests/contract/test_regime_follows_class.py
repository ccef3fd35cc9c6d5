"""The precession regime names the class the body was given (API.md, "The precession section").

``classification.kind`` calls moments equal within the request's ``tolerance``; the regime is then
``regular_precession`` for a symmetric top and ``spherical`` for a spherical top, with the symmetric
top's rates (Landau & Lifshitz §§33-36), even where the moments differ by more than rounding: a
cylinder written to a float32 STL, or moments a client calls equal with a coarser tolerance. The
trajectory stays the motion of the moments as they are; a warning says so.
"""

from __future__ import annotations

import math
import struct
from fractions import Fraction

import numpy as np
import pytest
from fastapi.testclient import TestClient

from tests.contract.helpers import analyze


def _symmetric_rates(i_perp: float, i_s: float, omega_body: list[float], unique: int) -> dict[str, float]:
    """L&L: omega = O3 (I3 - I1)/I1, |M|/I1, psi' = |M| cos(theta)(1/I3 - 1/I1), cos(theta) = I3 O3/|M|."""
    moments = [i_perp, i_perp, i_perp]
    moments[unique] = i_s
    m = math.sqrt(sum((i * w) ** 2 for i, w in zip(moments, omega_body, strict=True)))
    o3 = omega_body[unique]
    body = o3 * (i_s - i_perp) / i_perp
    return {
        "body_precession_rate": body,
        "space_precession_rate": m / i_perp,
        "spin_rate": i_s * o3 * (1 / i_s - 1 / i_perp),
        "nutation_angle": math.acos(i_s * o3 / m),
        "period": 2 * math.pi / abs(body),
    }


def test_moments_equal_within_the_requested_tolerance_precess_regularly(client: TestClient) -> None:
    # I1 = 2, I2 = 2.002 (0.067 % of I3 apart) called equal with tolerance 1e-2: an oblate symmetric top
    omega = [0.3, 0.4, 1.0]
    r = client.post("/v1/precession", json={"principal_moments": [2.0, 2.002, 3.0], "omega": omega, "tolerance": 1e-2})
    assert r.status_code == 200, r.text
    res = r.json()
    assert res["classification"]["kind"] == "symmetric_top" and res["classification"]["shape"] == "oblate"
    p = res["precession"]
    assert p["regime"] == "regular_precession"
    assert p["stable"] is True and "flip_interval" not in p
    mean = float((Fraction(2) + Fraction("2.002")) / 2)  # the equal pair's moment
    for key, value in _symmetric_rates(mean, 3.0, omega, 2).items():
        assert p[key] == pytest.approx(value, rel=1e-12), key
    assert any("tolerance" in w for w in res["warnings"]), res["warnings"]


def test_a_spherical_top_within_tolerance_is_the_spherical_regime(client: TestClient) -> None:
    r = client.post("/v1/precession", json={"principal_moments": [1.0, 1.001, 1.002], "omega": [1, 2, 3], "tolerance": 1e-2})
    res = r.json()
    assert res["classification"]["kind"] == "spherical_top"
    p = res["precession"]
    assert p["regime"] == "spherical" and p["stable"] is True
    for key in ("body_precession_rate", "spin_rate", "period", "flip_interval"):
        assert key not in p


def test_perpendicular_spin_of_a_symmetric_top_within_tolerance_is_permanent_rotation(client: TestClient) -> None:
    r = client.post("/v1/precession", json={"principal_moments": [2.0, 2.002, 3.0], "omega": [0.6, 0.8, 0.0], "tolerance": 1e-2})
    p = r.json()["precession"]
    assert p["regime"] == "permanent_rotation" and p["stable"] is True


def _float32_cylinder_stl(radius: float, height: float, sections: int, tilt: float) -> bytes:
    """A closed prism of ``sections`` sides about the axis (0, sin tilt, cos tilt), as a binary STL."""
    c, s = math.cos(tilt), math.sin(tilt)

    def rotate(p: tuple[float, float, float]) -> tuple[float, float, float]:
        x, y, z = p
        return (x, c * y - s * z, s * y + c * z)

    ring = [(radius * math.cos(2 * math.pi * k / sections), radius * math.sin(2 * math.pi * k / sections)) for k in range(sections)]
    bottom, top = [rotate((x, y, 0.0)) for x, y in ring], [rotate((x, y, height)) for x, y in ring]
    b0, t0 = rotate((0.0, 0.0, 0.0)), rotate((0.0, 0.0, height))
    tris = []
    for k in range(sections):
        j = (k + 1) % sections
        tris += [(b0, bottom[j], bottom[k]), (t0, top[k], top[j]), (bottom[k], bottom[j], top[j]), (bottom[k], top[j], top[k])]
    out = bytearray(80) + struct.pack("<I", len(tris))
    for tri in tris:
        out += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *v) for v in tri) + b"\0\0"
    return bytes(out)


def test_a_float32_cylinder_precesses_as_the_symmetric_top_it_is_classified(client: TestClient) -> None:
    data = _float32_cylinder_stl(0.3, 2.0, 64, 0.7)
    res = analyze(client, "cylinder.stl", data, omega="0.3,0.2,1")
    cls = res["classification"]
    assert cls["kind"] == "symmetric_top" and cls["shape"] == "prolate"
    i1, i2, i3 = res["principal"]["moments"]
    assert i1 < i2 < i3 and (i3 - i2) / i3 > 1e-12  # float32 vertices: the pair differs by more than rounding
    p = res["precession"]
    assert p["regime"] == "regular_precession"
    axes = np.asarray(res["principal"]["axes"])
    omega_body = list(axes @ [0.3, 0.2, 1.0])
    for key, value in _symmetric_rates((i2 + i3) / 2, i1, omega_body, 0).items():
        assert p[key] == pytest.approx(value, rel=1e-9), key


def _needle_rates(i1: float, i_perp: float, omega_body: list[float]) -> dict[str, float]:
    """A needle's free motion is the prolate top's (L&L §33), whatever its class's label."""
    return _symmetric_rates(i_perp, i1, omega_body, 0)


def test_a_needle_classified_a_linear_rotator_is_the_rotator_regime(client: TestClient) -> None:
    omega = [0.3, 0.2, 1.0]
    res = client.post("/v1/precession", json={"principal_moments": [1e-9, 1.0, 1.0], "omega": omega}).json()
    assert res["classification"]["kind"] == "linear_rotator"
    p = res["precession"]
    assert p["regime"] == "rotator" and p["stable"] is True
    want = _needle_rates(1e-9, 1.0, omega)
    # the rates of the needle itself: |M|/I_perp about M, its axis ~pi/2 from M (a rotator's)
    assert p["space_precession_rate"] == pytest.approx(want["space_precession_rate"], rel=1e-15)
    assert p["nutation_angle"] == pytest.approx(want["nutation_angle"], rel=1e-15)
    assert p["body_precession_rate"] == pytest.approx(want["body_precession_rate"], rel=1e-12)


def test_a_needle_spun_across_its_axis_is_the_rotator_regime(client: TestClient) -> None:
    res = client.post("/v1/precession", json={"principal_moments": [1e-9, 1.0, 1.0], "omega": [0.0, 0.6, 0.8]}).json()
    p = res["precession"]
    assert p["regime"] == "rotator"
    assert p["space_precession_rate"] == pytest.approx(1.0, rel=1e-15)
    assert p["nutation_angle"] == pytest.approx(math.pi / 2, rel=1e-15)


def test_a_needle_spun_about_its_own_axis_stays_a_permanent_rotation(client: TestClient) -> None:
    res = client.post("/v1/precession", json={"principal_moments": [1e-9, 1.0, 1.0], "omega": [2.0, 0.0, 0.0]}).json()
    assert res["precession"]["regime"] == "permanent_rotation"  # a real spin of a body with I1 > 0
