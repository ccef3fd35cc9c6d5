"""The contract in the repository is the shared contract, word for word (when the shared copy is beside the
checkout, as it is in CI); what this implementation adds lives in docs/api-extensions.md."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "API.md"


@pytest.mark.skipif(not SHARED.exists(), reason="the shared contract is not beside this checkout")
def test_docs_api_is_the_shared_contract() -> None:
    assert (ROOT / "docs" / "api.md").read_text(encoding="utf-8") == SHARED.read_text(encoding="utf-8")


def test_readme_links_resolve_inside_the_repository() -> None:
    import re

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    targets = [t for t in re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text) if "://" not in t]
    assert targets, "the README links to its documents"
    missing = [t for t in targets if not (ROOT / t).exists()]
    assert not missing, missing
    assert "../shared" not in text
