"""Which formats this installation can read: a reader whose package is missing is not offered.

The table lives beside the format sniffing (``load.sniff``), whose messages list the same formats.
"""

from __future__ import annotations

from ..load.sniff import OPTIONAL_READERS, unavailable_formats

__all__ = ["unavailable_formats", "OPTIONAL_READERS"]
