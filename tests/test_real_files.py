"""Every real file of tests/data/real is read right (against an independent exact reference) or refused with a reason."""

from __future__ import annotations

import pytest

from benchmarks.real_files import EXPECTED, KNOWN, run_one


@pytest.mark.parametrize("rel", sorted(EXPECTED))
def test_real_file_is_read_right_or_refused_with_a_reason(rel: str) -> None:
    row = run_one(rel)
    if rel in KNOWN:  # a known deviation, documented in docs/real-files.md: this fails once it is fixed
        assert row.outcome == "wrong", f"{rel} is now {row.outcome}: remove its 'known' note"
        return
    assert row.outcome in ("read right", "read, no reference", "refused"), f"{row.outcome}: {row.detail}"
    if row.outcome == "refused":
        assert len(row.detail) > 40  # a sentence, not a bare library message
