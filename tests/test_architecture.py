"""The borders between the stages: no import cycle, and no module imports a layer above its own.

The graph is read from the source (``ast``), not from ``sys.modules``, so every edge counts: imports at
module level, inside functions (lazy) and under ``if TYPE_CHECKING:``.  An edge goes to the module
that the import names: ``from . import x`` and ``from .pkg import x`` are edges to the submodule ``x``
when there is one, else to the package.  The layer table below is the one ``docs/architecture.md``
describes; a module the table does not name fails the test, so a new module is placed on purpose.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = "inertia"
SOURCE = ROOT / "service"

# Bottom to top.  A module may import modules of its own layer or below, never above.  Within a
# package, the first entry that is a prefix of the module's name decides (``motion`` covers
# ``motion.elliptic``); the most specific prefix wins.
LAYERS: list[tuple[str, list[str]]] = [
    (
        "kernels",
        [
            "errors",
            "tolerances",
            "conventions",
            "arrays",
            "integrals",
            "eigen",
            "ddouble",
            "cpus",
            "blocks",
            "cells",
            "elements",
            "vocabulary",
            "sections",
        ],
    ),
    ("body", ["body"]),
    ("geometry", ["topology", "seams", "solid", "surface"]),
    ("load", ["load", "cad.read", "cad.occ", "cad.green"]),  # green: the adapter's own face integrals
    ("mass geometry", ["mass.properties", "mass.points", "mass.geometry"]),
    ("refinement", ["mass.refine"]),
    ("mass", ["mass", "mass.material", "cad"]),
    ("principal", ["principal"]),
    ("classification", ["classification"]),
    ("motion", ["motion"]),
    ("derived", ["export", "frames", "rotational"]),
    ("results", ["options", "results", "report"]),
    ("pipeline", ["pipeline", "few_points"]),
    ("surfaces", ["api", "app", "batch", "cli", "web", "__main__", "_contract_names", ""]),
]


def module_name(path: Path) -> str:
    parts = list(path.relative_to(SOURCE).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join([PACKAGE, *parts])


def modules() -> dict[str, Path]:
    return {module_name(p): p for p in sorted(SOURCE.rglob("*.py"))}


def _is_package(path: Path) -> bool:
    return path.name == "__init__.py"


def _imports(tree: ast.AST) -> Iterator[tuple[str | None, int, list[str]]]:
    """(module, level, names) of every import statement, wherever it stands."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, 0, []
        elif isinstance(node, ast.ImportFrom):
            yield node.module, node.level, [alias.name for alias in node.names]


def edges(known: dict[str, Path] | None = None) -> dict[str, set[str]]:
    """module -> the package's modules it imports (itself excluded)."""
    known = modules() if known is None else known
    graph: dict[str, set[str]] = {}
    for name, path in known.items():
        here = name if _is_package(path) else name.rpartition(".")[0]
        targets: set[str] = set()
        for module, level, names in _imports(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            if level:
                base = here
                for _ in range(level - 1):
                    base = base.rpartition(".")[0]
                target = f"{base}.{module}" if module else base
            else:
                assert module is not None
                target = module
            if target != PACKAGE and not target.startswith(PACKAGE + "."):
                continue
            resolved = [f"{target}.{n}" for n in names if f"{target}.{n}" in known]
            if resolved:
                targets.update(resolved)
            if len(resolved) < len(names) or not names:
                while target not in known:  # ``import inertia.x.y`` of a name that is not a module
                    target = target.rpartition(".")[0]
                targets.add(target)
        targets.discard(name)
        graph[name] = targets
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def layer_of(name: str) -> int:
    """The index in ``LAYERS`` of a module, by its most specific listed prefix."""
    rel = name.removeprefix(PACKAGE).removeprefix(".")
    best: tuple[int, int] | None = None  # (prefix length, layer)
    for rank, (_, prefixes) in enumerate(LAYERS):
        for prefix in prefixes:
            matches = rel == prefix or (prefix and rel.startswith(prefix + ".")) or (not prefix and not rel)
            if matches and (best is None or len(prefix) > best[0]):
                best = (len(prefix), rank)
    if best is None:
        raise LookupError(f"{name} is in no layer of tests/test_architecture.py: place it in LAYERS")
    return best[1]


def upward(graph: dict[str, set[str]]) -> list[str]:
    bad = []
    for source, targets in sorted(graph.items()):
        for target in sorted(targets):
            if layer_of(target) > layer_of(source):
                bad.append(f"{source} ({LAYERS[layer_of(source)][0]}) imports {target} ({LAYERS[layer_of(target)][0]})")
    return bad


# --- the graph builder itself, on small sources with a known answer -----------------------------


def _graph_of(tmp_path: Path, files: dict[str, str]) -> dict[str, set[str]]:
    for rel, text in files.items():
        path = tmp_path / "service" / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    source = tmp_path / "service"
    known = {}
    for p in sorted(source.rglob("*.py")):
        parts = list(p.relative_to(source).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        known[".".join([PACKAGE, *parts])] = p
    return edges(known)


def test_builder_sees_lazy_type_checking_and_submodule_edges(tmp_path: Path) -> None:
    graph = _graph_of(
        tmp_path,
        {
            "__init__.py": "",
            "a.py": "def f():\n    from .b import g\n",
            "b.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .pkg import sub, thing\n",
            "pkg/__init__.py": "from . import sub\n",
            "pkg/sub.py": "from .. import a\nimport inertia.pkg.sub\nimport inertia.b.nothing\nimport numpy\n",
        },
    )
    assert graph["inertia.a"] == {"inertia.b"}
    assert graph["inertia.b"] == {"inertia.pkg.sub", "inertia.pkg"}
    assert graph["inertia.pkg"] == {"inertia.pkg.sub"}
    assert graph["inertia.pkg.sub"] == {"inertia.a", "inertia.b"}
    assert cycles(graph) == [["inertia.a", "inertia.b", "inertia.pkg", "inertia.pkg.sub"]]


def test_layer_lookup_prefers_the_most_specific_prefix() -> None:
    assert layer_of("inertia") == len(LAYERS) - 1
    assert LAYERS[layer_of("inertia.motion.elliptic")][0] == "motion"
    assert LAYERS[layer_of("inertia.errors")][0] == "kernels"


# --- the package ----------------------------------------------------------------------------------


def test_every_module_is_placed_in_a_layer() -> None:
    unplaced = []
    for name in modules():
        try:
            layer_of(name)
        except LookupError:
            unplaced.append(name)
    assert unplaced == [], f"modules in no layer of LAYERS: {unplaced}"


def test_no_import_cycle() -> None:
    found = cycles(edges())
    assert found == [], "import cycles (lazy and TYPE_CHECKING imports count):\n" + "\n".join(" <-> ".join(c) for c in found)


def test_no_module_imports_a_layer_above_its_own() -> None:
    bad = upward(edges())
    assert bad == [], "imports against the layer order:\n" + "\n".join(bad)


def test_docs_describe_the_same_layers() -> None:
    """docs/architecture.md has a row per layer, in this order, naming each module prefix of it."""
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    rows = [line for line in text.splitlines() if line.startswith("| ") and not line.startswith("| layer")]
    rows = [r for r in rows if not set(r) <= set("|- ")]
    assert [r.split("|")[1].strip() for r in rows] == [name for name, _ in LAYERS]
    for row, (_, prefixes) in zip(rows, LAYERS):
        cell = row.split("|")[2]
        for prefix in prefixes:
            if prefix:
                shown = prefix.replace(".", "/")
                assert f"`{prefix}" in cell or f"`{shown}" in cell, (prefix, row)


if __name__ == "__main__":  # print the graph's problems without pytest
    g = edges()
    for c in cycles(g):
        print("cycle:", " <-> ".join(c))
    for line in upward(g):
        print("upward:", line)
