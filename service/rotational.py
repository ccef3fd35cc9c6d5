"""Rotational constants of a rigid rotor (molecular spectroscopy).

A = h / (8 pi^2 I1) >= B = h / (8 pi^2 I2) >= C = h / (8 pi^2 I3), in
frequency units (MHz) and wavenumbers (cm^-1, divided by c), with the CODATA
values of h and c carried by ``scipy.constants`` (Gordy & Cook, Microwave
Molecular Spectra, 3rd ed., eq. 2.29).  A linear molecule has the one
constant B of its two equal moments.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["RotationalConstants", "rotational_constants"]


@dataclass(frozen=True, slots=True)
class RotationalConstants:
    """A >= B >= C (or B alone for a linear molecule) in MHz and in cm^-1."""

    mhz: tuple[float, ...]
    wavenumber: tuple[float, ...]


def rotational_constants(moments: NDArray[np.float64], linear: bool) -> RotationalConstants | None:
    """Constants of ascending principal moments [kg m^2]; None when a moment they need is not positive."""
    from scipy.constants import c, h

    I1, I2, I3 = (float(m) for m in moments)
    needed = (0.5 * (I2 + I3),) if linear else (I1, I2, I3)
    if not all(i > 0 for i in needed):
        return None
    hz = tuple(h / (8 * math.pi**2 * i) for i in needed)
    return RotationalConstants(tuple(v * 1e-6 for v in hz), tuple(v / c / 100 for v in hz))
