"""Results as the API's JSON: kept for its old import path; the serialiser is :mod:`results`."""

from __future__ import annotations

from .results import analysis_dict, classification_dict, precession_dict, principal_dict, radii_of_gyration

__all__ = ["analysis_dict", "precession_dict", "principal_dict", "classification_dict", "radii_of_gyration"]
