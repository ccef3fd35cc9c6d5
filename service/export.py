"""The inertial element of robot description formats: URDF, SDFormat and MJCF.

Each snippet holds the body's mass, centre of mass and inertia in SI units, in
the input frame, numbers written with 17 significant digits (enough for every
float64 to read back bit for bit):

- URDF (ROS ``urdf`` XML specification, ``<inertial>``): ``<origin xyz rpy>``
  at the centre of mass with ``rpy="0 0 0"``, so the six ``<inertia>``
  components are the tensor about the centre of mass along the link's axes.
- SDFormat (``inertial.sdf`` of the SDFormat specification): ``<pose>x y z 0 0 0</pose>``,
  ``<mass>``, ``<inertia>`` with ``ixx ... izz`` about the centre of mass.
- MJCF (MuJoCo XML reference, ``body/inertial``): ``pos``, ``quat`` (w x y z)
  rotating the principal (inertial) frame into the body frame, ``mass`` and
  ``diaginertia`` (the principal moments in that frame's axis order).

A body a simulator would refuse is ``InvalidInertiaError`` instead of a
snippet.  MuJoCo's compiler (``user_objects.cc``, ``mjCBody::Compile`` and
the model checks) rejects negative mass or moments, principal moments that
break the triangle inequality ``A + B >= C`` (compared exactly, with no
tolerance), and, for a body that can move, a mass or moment below
``mjMINVAL`` = 1e-15.  URDF and SDF tensors are diagonalised again by their
reader, which may move each moment by a few units in the last place; a
planar body (I1 + I2 = I3 exactly, for a lamina or a planar point set) sits
on the boundary of the inequality, so its largest moment is lowered by a
margin of ``PLANAR_MARGIN`` relative (named in a warning) to keep the
inequality true after that rounding.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .arrays import freeze_fields
from .errors import InvalidInertiaError, InvalidParameterError
from .tolerances import EPS
from .vocabulary import ExportFormat, values

__all__ = ["EXPORT_FORMATS", "MJ_MINVAL", "PLANAR_MARGIN", "Inertial", "Snippet", "inertial_snippet"]

EXPORT_FORMATS = values(ExportFormat)

# mjMINVAL of MuJoCo's mjmodel.h: moving bodies need mass and principal moments above it [kg, kg m^2]
MJ_MINVAL = 1e-15

# relative room left below the triangle inequality for readers that re-diagonalise a tensor
# (URDF, SDF): a 3x3 symmetric eigen-solver moves each eigenvalue by a few eps of the largest
PLANAR_MARGIN = 64 * EPS


@dataclass(frozen=True, slots=True)
class Inertial:
    """What a snippet states, SI units, input frame.

    mass [kg]; center_of_mass (3,) [m]; tensor (3, 3) [kg m^2] about the centre of
    mass; moments (3,) ascending [kg m^2]; axes (3, 3) rows are the principal axes
    (right-handed); quaternion [w, x, y, z] principal frame -> input frame;
    linear : the body is a linear rotator (or a single point);
    relative_error : the moments' relative error estimate.
    """

    mass: float
    center_of_mass: NDArray[np.float64]
    tensor: NDArray[np.float64]
    moments: NDArray[np.float64]
    axes: NDArray[np.float64]
    quaternion: NDArray[np.float64]
    linear: bool = False
    relative_error: float = 0.0

    def __post_init__(self) -> None:
        freeze_fields(self, {"center_of_mass": (3,), "tensor": (3, 3), "moments": (3,), "axes": (3, 3), "quaternion": (4,)})


@dataclass(frozen=True, slots=True)
class Snippet:
    """An export: the format, the XML text, and what had to be assumed to write it."""

    format: str
    text: str
    warnings: tuple[str, ...] = ()


def _num(x: float) -> str:
    """17 significant digits: every float64 reads back exactly; no negative zero."""
    return f"{float(x) + 0.0:.17g}"


def _nums(values: NDArray[np.float64] | list[float]) -> str:
    return " ".join(_num(v) for v in values)


def _check(body: Inertial, fmt: str, name: str) -> None:
    """Refuse what a simulator refuses, with the reason."""
    who = f"{name}: " if name else ""
    i1, i3 = float(body.moments[0]), float(body.moments[2])
    if not (np.isfinite(body.mass) and body.mass > 0):
        raise InvalidInertiaError(
            f"{who}the mass {body.mass!r} kg is not positive; simulators refuse such a body", reason="mass", format=fmt
        )
    if body.linear or i3 <= 0:
        raise InvalidInertiaError(
            f"{who}the body is a linear rotator or a single point (smallest principal moment {i1:.3g} kg m^2 is zero); "
            "a simulator needs three positive moments: give the body some thickness",
            reason="zero_moment",
            format=fmt,
            moments=body.moments.tolist(),
        )
    # relative_error bounds each moment's error relative to itself: below 1, a positive moment is positive
    if not (i1 > 0 and body.relative_error < 1):
        raise InvalidInertiaError(
            f"{who}the smallest principal moment ({i1:.3g} kg m^2) is not positive within its error (largest {i3:.3g}); "
            "a simulator needs three positive moments: give the body some thickness",
            reason="zero_moment",
            format=fmt,
            moments=body.moments.tolist(),
        )
    if fmt in (ExportFormat.MJCF, ExportFormat.URDF) and (body.mass < MJ_MINVAL or i1 < MJ_MINVAL):
        raise InvalidInertiaError(
            f"{who}MuJoCo refuses a moving body whose mass or principal moment is below mjMINVAL = 1e-15 "
            f"(here mass {body.mass:.3g} kg, smallest moment {i1:.3g} kg m^2); scale the model up or use sdf",
            reason="below_mjminval",
            format=fmt,
            mass=body.mass,
            moments=body.moments.tolist(),
        )


def _triangle(body: Inertial, margin: float, name: str) -> tuple[NDArray[np.float64], NDArray[np.float64], tuple[str, ...]]:
    """Moments and tensor with I1 + I2 >= I3 (1 + margin) as written, and the warning if i3 was lowered.

    Mathematically I1 + I2 >= I3 for every body (equality: planar); a shortfall
    is rounding, and only a planar body comes within the margin.
    """
    moments = np.array(body.moments, dtype=np.float64)
    i1, i2, i3 = (float(m) for m in moments)
    target = i1 + i2 - margin * i3
    if margin == 0.0 and i1 + i2 >= i3:
        return moments, np.array(body.tensor), ()
    if margin > 0.0 and i1 + i2 - i3 >= margin * i3:
        return moments, np.array(body.tensor), ()
    shortfall = (i3 - target) / i3
    if shortfall > max(body.relative_error, 0.0) + 2 * margin + 8 * EPS:
        raise InvalidInertiaError(
            f"{name + ': ' if name else ''}the principal moments {i1:.6g}, {i2:.6g}, {i3:.6g} kg m^2 break the triangle "
            "inequality I1 + I2 >= I3, which simulators enforce",
            reason="triangle_inequality",
            moments=moments.tolist(),
        )
    moments[2] = target
    while moments[0] + moments[1] < moments[2]:  # the sum may round below the target
        moments[2] = np.nextafter(moments[2], 0.0)
    axis = body.axes[2]
    tensor = np.array(body.tensor) - (i3 - float(moments[2])) * np.outer(axis, axis)
    tensor = 0.5 * (tensor + tensor.T)
    warning = (
        f"export: {name + ' ' if name else ''}planar body (I1 + I2 = I3): the largest principal moment "
        f"was lowered by {shortfall:.2g} relative so that simulators' check I1 + I2 >= I3 holds after rounding"
    )
    return moments, tensor, (warning,)


def inertial_snippet(fmt: str, body: Inertial, name: str = "") -> Snippet:
    """The inertial element of ``fmt`` ("urdf", "sdf" or "mjcf") for ``body``."""
    if fmt not in EXPORT_FORMATS:
        raise InvalidParameterError(f"export must be one of {', '.join(EXPORT_FORMATS)}, got {fmt!r}", parameter="export")
    _check(body, fmt, name)
    # MJCF states the principal moments themselves, compared exactly by MuJoCo; URDF and SDF readers re-diagonalise
    moments, tensor, warnings = _triangle(body, 0.0 if fmt == ExportFormat.MJCF else PLANAR_MARGIN, name)
    c = body.center_of_mass
    if fmt == ExportFormat.MJCF:
        text = (
            f'<inertial pos="{_nums(c)}" quat="{_nums(body.quaternion)}" mass="{_num(body.mass)}" diaginertia="{_nums(moments)}"/>'
        )
        return Snippet(fmt, text, warnings)
    t = {
        "ixx": tensor[0, 0],
        "ixy": tensor[0, 1],
        "ixz": tensor[0, 2],
        "iyy": tensor[1, 1],
        "iyz": tensor[1, 2],
        "izz": tensor[2, 2],
    }
    if fmt == ExportFormat.URDF:
        components = " ".join(f'{k}="{_num(v)}"' for k, v in t.items())
        text = (
            f'<inertial>\n  <origin xyz="{_nums(c)}" rpy="0 0 0"/>\n  <mass value="{_num(body.mass)}"/>\n'
            f"  <inertia {components}/>\n</inertial>"
        )
        return Snippet(fmt, text, warnings)
    components = "".join(f"\n    <{k}>{_num(v)}</{k}>" for k, v in t.items())
    text = (
        f"<inertial>\n  <pose>{_nums(c)} 0 0 0</pose>\n  <mass>{_num(body.mass)}</mass>\n"
        f"  <inertia>{components}\n  </inertia>\n</inertial>"
    )
    return Snippet(fmt, text, warnings)
