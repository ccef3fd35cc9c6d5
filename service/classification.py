"""Classification of a rigid body by its principal moments (Landau & Lifshitz §32).

- spherical top: I1 = I2 = I3
- symmetric top: exactly two equal; prolate when the unique moment is the
  smallest (I1 < I2 = I3), oblate when it is the largest (I1 = I2 < I3)
- linear rotator: I1 = 0 and I2 = I3 (collinear masses, a thin rod)
- asymmetric top: all different

Ray's asymmetry parameter kappa = (2B - A - C) / (A - C) on the rotational
constants A = 1/I1 >= B = 1/I2 >= C = 1/I3 (Ray, Z. Physik 78, 1932).
"""

from __future__ import annotations

import enum
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from .principal import PrincipalFrame, equal_moment_pairs

__all__ = ["RotorClass", "Margins", "Classification", "classify", "classify_moments", "ray_asymmetry"]


class RotorClass(enum.Enum):
    ASYMMETRIC = "asymmetric_top"
    SYMMETRIC_PROLATE = "symmetric_top/prolate"
    SYMMETRIC_OBLATE = "symmetric_top/oblate"
    SPHERICAL = "spherical_top"
    LINEAR = "linear_rotator"

    @property
    def kind(self) -> str:
        """The API's ``classification.kind``."""
        return self.value.split("/")[0]

    @property
    def shape(self) -> str | None:
        """The API's ``classification.shape`` (symmetric tops only)."""
        parts = self.value.split("/")
        return parts[1] if len(parts) == 2 else None

    @property
    def is_symmetric(self) -> bool:
        return self in (RotorClass.SYMMETRIC_PROLATE, RotorClass.SYMMETRIC_OBLATE)


@dataclass(frozen=True, slots=True)
class Margins:
    """The relative gaps that decided a classification, each to compare with its ``tolerance`` [1].

    gap12 : (I2 - I1) / I3.   gap23 : (I3 - I2) / I3.
    smallest : I1 / I3 (a linear rotator's is within tolerance of 0).
    planarity : |I1 + I2 - I3| / I3 (a lamina's or a planar point set's is within tolerance of 0).
    All are 0 for a body whose moments are all zero (a single point).
    """

    gap12: float = 0.0
    gap23: float = 0.0
    smallest: float = 0.0
    planarity: float = 0.0


@dataclass(frozen=True, slots=True)
class Classification:
    """What kind of top a body is, and the margins that decided it.

    symmetry_axis : (3,) unit vector in the input frame, or None.
    asymmetry : Ray's kappa, or None (spherical tops and rotators).
    margins : the relative gaps that decided it (:class:`Margins`), to compare with ``tolerance``.
    """

    rotor: RotorClass
    symmetry_axis: NDArray[np.float64] | None
    asymmetry: float | None
    planar: bool
    tolerance: float
    margins: Margins = field(default_factory=Margins)

    @property
    def kind(self) -> str:
        return self.rotor.kind

    @property
    def shape(self) -> str | None:
        return self.rotor.shape


def ray_asymmetry(moments: Sequence[float] | NDArray[np.float64]) -> float:
    """Ray's kappa from ascending moments, as [I3(I1-I2) + I1(I3-I2)] / [I2(I3-I1)].

    That form (kappa multiplied through by I1 I2 I3) uses only moment gaps,
    so it does not lose digits when moments are nearly equal.
    """
    top = float(moments[2])
    i1, i2, i3 = (float(x) / top for x in moments)  # kappa is scale-free; this keeps products in range
    return (i3 * (i1 - i2) + i1 * (i3 - i2)) / (i2 * (i3 - i1))


def classify(frame: PrincipalFrame, tolerance: float | None = None) -> Classification:
    """Classify the body whose principal frame is ``frame``."""
    return classify_moments(frame.moments.tolist(), frame.axes, frame.tolerance if tolerance is None else tolerance)


def classify_moments(moments: list[float], axes: NDArray[np.float64], tol: float) -> Classification:
    """``classify`` on the ascending moments and the principal axes (rows) of a frame."""
    i1, i2, i3 = moments
    if i3 == 0.0:  # all mass at one point: no axis is distinguished, every moment is zero
        return Classification(RotorClass.SPHERICAL, None, None, True, tol, Margins())
    margins = Margins(gap12=(i2 - i1) / i3, gap23=(i3 - i2) / i3, smallest=i1 / i3, planarity=abs(i1 + i2 - i3) / i3)
    pairs = equal_moment_pairs(moments, tol)
    planar = margins.planarity <= tol
    if len(pairs) == 3:
        return Classification(RotorClass.SPHERICAL, None, None, planar, tol, margins)
    if pairs == ((1, 2),) and margins.smallest <= tol:
        return Classification(RotorClass.LINEAR, axes[0].copy(), None, planar, tol, margins)
    kappa = ray_asymmetry(moments)
    if pairs == ((1, 2),):
        return Classification(RotorClass.SYMMETRIC_PROLATE, axes[0].copy(), kappa, planar, tol, margins)
    if pairs == ((0, 1),):
        return Classification(RotorClass.SYMMETRIC_OBLATE, axes[2].copy(), kappa, planar, tol, margins)
    return Classification(RotorClass.ASYMMETRIC, None, kappa, planar, tol, margins)
