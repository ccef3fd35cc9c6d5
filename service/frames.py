"""Mass properties in a frame the user names, as CAD mass-property dialogs report them.

The named frame is given by a unit quaternion q = [w, x, y, z] whose rotation R
carries the named frame's axes into the input frame (column i of R is the
named frame's axis i in input-frame components).  A vector's components along
the named axes are then R^T v, and a tensor's are R^T I R (the tensor
transformation rule, Landau & Lifshitz §32).  Positions are taken relative to
the input origin, or to the reference point when one is given.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .arrays import freeze_fields
from .conventions import matrix_from_quaternion
from .errors import InvalidParameterError

__all__ = ["NamedFrame", "named_frame", "frame_rotation", "frame_norm_warning", "UNIT_QUATERNION_TOLERANCE", "TYPED_ROUNDING"]

# a quaternion typed with 7-8 significant digits per component has a norm within ~1e-7 of one, and one
# typed with four (0.7071) within ~1e-4: such a quaternion is normalised, named in a warning past
# TYPED_ROUNDING; beyond UNIT_QUATERNION_TOLERANCE it is more likely a mistake (Euler angles, a vector)
# than rounding, so it is refused
UNIT_QUATERNION_TOLERANCE = 1e-3
TYPED_ROUNDING = 1e-6


def _norm(q: Sequence[float] | NDArray[np.float64]) -> float:
    return math.sqrt(math.fsum(float(v) * float(v) for v in q))


def frame_norm_warning(quaternion: Sequence[float]) -> str | None:
    """A warning naming the normalisation of a frame quaternion typed with few digits; None if at rounding."""
    norm = _norm(quaternion)
    if abs(norm - 1.0) <= TYPED_ROUNDING:
        return None
    return f"the frame quaternion's norm is {norm:.9g}, not 1; it was normalised (divided by its norm)"


@dataclass(frozen=True, slots=True)
class NamedFrame:
    """The ``frame`` section: components along the named frame's axes (SI).

    quaternion : (4,) the unit quaternion as used (normalised).
    center_of_mass : (3,) [m] relative to the input origin, or to ``reference``.
    inertia_tensor : (3, 3) [kg m^2] about the centre of mass.
    reference_inertia : (3, 3) [kg m^2] about the reference point, or None.
    """

    quaternion: NDArray[np.float64]
    center_of_mass: NDArray[np.float64]
    inertia_tensor: NDArray[np.float64]
    reference_inertia: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        freeze_fields(self, {"quaternion": (4,), "center_of_mass": (3,), "inertia_tensor": (3, 3)})
        if self.reference_inertia is not None:
            freeze_fields(self, {"reference_inertia": (3, 3)})


def frame_rotation(quaternion: Sequence[float]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The normalised quaternion and its rotation matrix; refuses one that is not a unit quaternion."""
    try:
        q = np.array([float(v) for v in quaternion], dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidParameterError("frame must be four numbers w,x,y,z", parameter="frame") from exc
    if q.shape != (4,) or not np.all(np.isfinite(q)):
        raise InvalidParameterError("frame must be four finite numbers w,x,y,z (a unit quaternion)", parameter="frame")
    norm = _norm(q)
    if abs(norm - 1.0) > UNIT_QUATERNION_TOLERANCE:
        raise InvalidParameterError(
            f"frame must be a unit quaternion w,x,y,z (its norm is {norm:.9g}); scalar first, e.g. 1,0,0,0", parameter="frame"
        )
    q = q / norm
    return q, matrix_from_quaternion(q)


def named_frame(
    quaternion: Sequence[float],
    center_of_mass: NDArray[np.float64],
    inertia_tensor: NDArray[np.float64],
    reference: NDArray[np.float64] | None = None,
    reference_inertia: NDArray[np.float64] | None = None,
) -> NamedFrame:
    """Centre of mass [m] and tensors [kg m^2] (input frame) re-expressed along the named frame's axes."""
    q, R = frame_rotation(quaternion)
    origin = np.zeros(3) if reference is None else np.asarray(reference, dtype=np.float64)
    com = R.T @ (np.asarray(center_of_mass, dtype=np.float64) - origin)
    tensor = _rotated(R, inertia_tensor)
    ref = None if reference_inertia is None else _rotated(R, reference_inertia)
    return NamedFrame(q, com, tensor, ref)


def _rotated(R: NDArray[np.float64], tensor: NDArray[np.float64]) -> NDArray[np.float64]:
    out: NDArray[np.float64] = R.T @ np.asarray(tensor, dtype=np.float64) @ R
    return 0.5 * (out + out.T)  # symmetric to the last bit
