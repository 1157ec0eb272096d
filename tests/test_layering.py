"""The package's import graph flows one way (issue 8 item 3).

Layers, lowest first: ``kinematics`` -> ``materials`` -> ``analytic``, ``fem``, ``networks``, ``io``
-> ``multiscale``, ``valve`` -> ``papers`` -> ``cli``. A module may import from its own layer (without
cycles) and from lower layers only. Imports inside functions are counted like the others, so a cycle
cannot hide behind one; only the CLI may import inside functions (for start-up time).
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "skvalve"
LAYERS = {
    "kinematics": 0, "materials": 1, "analytic": 2, "fem": 2, "networks": 2, "io": 2,
    "multiscale": 3, "valve": 3, "papers": 4, "__init__": 5, "cli": 6, "__main__": 6,
}


def _module_name(path: Path, package: Path) -> str:
    parts = path.relative_to(package.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _is_package(path: Path) -> bool:
    return path.name == "__init__.py"


def _imports(path: Path, package: Path) -> list[tuple[str, int, bool]]:
    """(imported skvalve module, line, inside a function) for every import in the file."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    name = _module_name(path, package)
    base = name.split(".") if _is_package(path) else name.split(".")[:-1]
    found = []

    def visit(node, nested: bool) -> None:
        for child in ast.iter_child_nodes(node):
            inner = nested or isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda)
            if isinstance(child, ast.Import):
                found.extend((alias.name, child.lineno, inner) for alias in child.names
                             if alias.name.split(".")[0] == "skvalve")
            elif isinstance(child, ast.ImportFrom):
                if child.level:
                    anchor = base[: len(base) - child.level + 1]
                    module = ".".join(anchor + ([child.module] if child.module else []))
                else:
                    module = child.module or ""
                if module.split(".")[0] == "skvalve":
                    # "from pkg import sub" imports pkg.sub when sub is a module
                    for alias in child.names:
                        candidate = f"{module}.{alias.name}"
                        target = candidate if _exists(candidate, package) else module
                        found.append((target, child.lineno, inner))
            visit(child, inner)

    visit(tree, False)
    return found


def _exists(module: str, package: Path) -> bool:
    path = package.parent.joinpath(*module.split("."))
    return path.with_suffix(".py").exists() or (path / "__init__.py").exists()


def _layer(module: str) -> int:
    parts = module.split(".")
    return LAYERS["__init__"] if len(parts) == 1 else LAYERS.get(parts[1], LAYERS["papers"])


def _graph(package: Path = PACKAGE) -> dict[str, list[tuple[str, int, bool]]]:
    return {_module_name(path, package): _imports(path, package) for path in sorted(package.rglob("*.py"))}


def _cycle(edges: dict[str, set[str]]) -> list[str] | None:
    """One cycle of the directed graph, or None (iterative DFS)."""
    colour: dict[str, int] = {}
    for root in sorted(edges):
        if colour.get(root):
            continue
        stack = [(root, iter(sorted(edges.get(root, ()))))]
        path = [root]
        colour[root] = 1
        while stack:
            node, children = stack[-1]
            for child in children:
                if colour.get(child, 0) == 1:
                    return path[path.index(child):] + [child]
                if colour.get(child, 0) == 0:
                    colour[child] = 1
                    path.append(child)
                    stack.append((child, iter(sorted(edges.get(child, ())))))
                    break
            else:
                colour[node] = 2
                path.pop()
                stack.pop()
    return None


def test_the_package_has_the_expected_subpackages():
    names = {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    assert {"materials", "analytic", "fem", "networks", "io", "multiscale", "valve", "papers"} <= names


def test_no_upward_imports():
    upward = []
    for module, imports in _graph().items():
        for target, line, _ in imports:
            if _layer(target) > _layer(module):
                upward.append(f"{module}:{line} imports {target}")
    assert not upward, "upward imports:\n" + "\n".join(upward)


def test_no_imports_inside_functions_outside_the_cli():
    hidden = [f"{module}:{line} imports {target}" for module, imports in _graph().items()
              for target, line, inner in imports if inner and _layer(module) < LAYERS["cli"]]
    assert not hidden, "imports inside functions:\n" + "\n".join(hidden)


def test_no_import_cycles_between_modules():
    edges = {module: {t for t, _, _ in imports if t != module} for module, imports in _graph().items()}
    cycle = _cycle(edges)
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_no_import_cycles_between_subpackages():
    edges: dict[str, set[str]] = {}
    for module, imports in _graph().items():
        source = ".".join(module.split(".")[:2])
        for target, _, _ in imports:
            target = ".".join(target.split(".")[:2])
            if target != source and target != "skvalve" and source != "skvalve":
                edges.setdefault(source, set()).add(target)
    cycle = _cycle(edges)
    assert cycle is None, "subpackage cycle: " + " -> ".join(cycle)


def test_the_checker_sees_a_hidden_cycle_and_an_upward_edge(tmp_path):
    """The detector itself: a two-module cycle through a function-level import and an upward edge."""
    root = tmp_path / "skvalve"
    (root / "fem").mkdir(parents=True)
    (root / "__init__.py").write_text("")
    (root / "fem" / "__init__.py").write_text("")
    (root / "fem" / "a.py").write_text("from . import b\n")
    (root / "fem" / "b.py").write_text("def f():\n    from .a import g\n")
    (root / "kinematics.py").write_text("from .fem import a\n")
    graph = _graph(root)
    edges = {m: {t for t, _, _ in imps if t != m} for m, imps in graph.items()}
    assert _cycle(edges) == ["skvalve.fem.a", "skvalve.fem.b", "skvalve.fem.a"]
    assert [inner for _, _, inner in graph["skvalve.fem.b"]] == [True]
    assert graph["skvalve.kinematics"] == [("skvalve.fem.a", 1, False)]
    assert _layer("skvalve.fem.a") > _layer("skvalve.kinematics")
