"""tests/ may use benchmarks/ (its cases, exact references and harness), never the reverse, and
neither reaches the other through ``sys.path``: both are packages imported from the repository root."""

from __future__ import annotations

import ast
import re
from pathlib import Path

from tests.support.paths import ROOT


def _imported(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
    return names


SYS_PATH_CHANGE = re.compile(r"sys\.path\s*(\.\s*(insert|append|extend)\b|\[|\+?=)")


def _sources(folder: str) -> list[Path]:
    return sorted((ROOT / folder).rglob("*.py"))


def test_benchmarks_never_import_the_tests() -> None:
    bad = [
        f"{p.relative_to(ROOT)} imports {name}"
        for p in _sources("benchmarks")
        for name in _imported(p)
        if name == "tests" or name.startswith("tests.")
    ]
    assert not bad, bad


def test_no_sys_path_changes_in_tests_or_benchmarks() -> None:
    bad = [
        str(p.relative_to(ROOT))
        for folder in ("tests", "benchmarks")
        for p in _sources(folder)
        if p.resolve() != Path(__file__).resolve() and SYS_PATH_CHANGE.search(p.read_text(encoding="utf-8"))
    ]
    assert not bad, bad


def test_the_checks_see_an_import_of_the_tests_and_a_path_change(tmp_path: Path) -> None:
    assert all(SYS_PATH_CHANGE.search(c) for c in ("sys.path.insert(0, x)", "sys.path += [x]", "sys.path[:0] = [x]"))
    assert not SYS_PATH_CHANGE.search("print(sys.path)")
    source = tmp_path / "x.py"
    source.write_text("import os\nfrom tests.support import meshes\nfrom . import local\n", encoding="utf-8")
    assert _imported(source) == {"os", "tests.support"}
