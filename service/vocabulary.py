"""The closed sets of the API, each spelled once: the CLI's choices, the options' checks, the request and
response schemas and the results use these.

Every set that a client sends or reads as a string is a ``StrEnum`` (``MotionMethod`` is a plain ``Enum``,
as the motion stage dispatches on it): its members compare equal to, and serialise as, the same strings.
No numpy here: the command line builds its parser from these before anything heavy is imported.
"""

from __future__ import annotations

import enum
import functools

__all__ = [
    "MotionMethod",
    "Model",
    "Geometry",
    "Isotopes",
    "MassUnit",
    "ExportFormat",
    "SourceKind",
    "UnitsFrom",
    "Regime",
    "RotorKind",
    "RotorShape",
    "MODELS",
    "METHODS",
    "values",
]


class MotionMethod(enum.Enum):
    """The API's ``method``: how Omega(t) and the attitude are computed."""

    EXACT = "exact"
    DOP853 = "dop853"
    RK45 = "rk45"
    SPLITTING = "splitting"


class Model(enum.StrEnum):
    """The API's ``model``: a closed surface or volume mesh bounds a solid; a thin shell is a surface with a wall."""

    SOLID = "solid"
    SHELL = "shell"


class Geometry(enum.StrEnum):
    """The API's ``geometry`` (CAD files): integrate the exact B-rep, or a tessellation of it."""

    BREP = "brep"
    MESH = "mesh"


class Isotopes(enum.StrEnum):
    """The API's ``isotopes``: masses of atoms named by element."""

    STANDARD = "standard"  # standard atomic weights
    ABUNDANT = "abundant"  # the most abundant isotope


class MassUnit(enum.StrEnum):
    """The API's ``mass_unit`` of point masses."""

    KG = "kg"
    U = "u"  # unified atomic mass unit (dalton)


class ExportFormat(enum.StrEnum):
    """The API's ``export``: the robot description formats whose inertial element is written."""

    URDF = "urdf"
    SDF = "sdf"
    MJCF = "mjcf"


class SourceKind(enum.StrEnum):
    """``source.kind``: what the input held."""

    MESH = "mesh"  # a surface
    VOLUME = "volume"  # volume cells
    POINTS = "points"  # point masses
    CAD = "cad"  # B-rep solids


class UnitsFrom(enum.StrEnum):
    """``source.units_from``: where the length unit applied to the input came from."""

    REQUEST = "request"
    FILE = "file"
    DEFAULT = "default"


class Regime(enum.Enum):
    """The API's ``precession.regime``."""

    REST = "rest"
    PERMANENT_ROTATION = "permanent_rotation"
    SPHERICAL = "spherical"
    REGULAR_PRECESSION = "regular_precession"
    ASYMMETRIC = "asymmetric"
    ROTATOR = "rotator"


class RotorKind(enum.StrEnum):
    """The API's ``classification.kind``."""

    SPHERICAL_TOP = "spherical_top"
    SYMMETRIC_TOP = "symmetric_top"
    ASYMMETRIC_TOP = "asymmetric_top"
    LINEAR_ROTATOR = "linear_rotator"


class RotorShape(enum.StrEnum):
    """The API's ``classification.shape`` of a symmetric top."""

    PROLATE = "prolate"
    OBLATE = "oblate"


@functools.cache  # a closed set never changes; options are checked against these on every request
def values(members: type[enum.Enum]) -> tuple[str, ...]:
    """The strings of a closed set, in its order (the CLI's choices, the schema's enum)."""
    return tuple(str(m.value) for m in members)


METHODS: tuple[str, ...] = values(MotionMethod)
MODELS: tuple[str, ...] = values(Model)
