"""The public surface is a contract: ``inertia.__all__`` is pinned here, each name resolves to what it says,
and the version has one source."""

from __future__ import annotations

import types
from importlib.metadata import version

import inertia

PUBLIC = {
    "AnalysisOptions",
    "AnalysisResult",
    "Classification",
    "InertiaTensor",
    "Loaded",
    "MassProperties",
    "PrincipalFrame",
    "RotorClass",
    "ServiceError",
    "Tolerances",
    "analyze",
    "analyze_points",
    "classify",
    "load_body",
    "mass_properties",
    "precession",
    "principal_frame",
}


def test_all_is_pinned() -> None:
    assert set(inertia.__all__) == PUBLIC
    assert len(inertia.__all__) == len(PUBLIC)


def test_every_public_name_resolves_and_none_is_a_module() -> None:
    for name in inertia.__all__:
        value = getattr(inertia, name)
        assert not isinstance(value, types.ModuleType), name
        assert getattr(value, "__module__", "inertia").startswith("inertia"), name


def test_version_has_one_source() -> None:
    assert inertia.__version__ == version("inertia-service")
