"""The closed sets of the API, each spelled once: the CLI's choices, the options' checks and the results use these.

No numpy here: the command line builds its parser from these before anything heavy is imported.
"""

from __future__ import annotations

import enum

__all__ = ["MotionMethod", "Model", "MODELS", "METHODS"]


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


METHODS: tuple[str, ...] = tuple(m.value for m in MotionMethod)
MODELS: tuple[str, ...] = tuple(m.value for m in Model)
