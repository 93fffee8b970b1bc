"""The package's import graph against the layer order in docs/DESIGN.md: no import points up a layer and no
imports form a cycle (module-level and function-local imports alike)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "spacepol"


def layers() -> dict[str, int]:
    """{top-level module or subpackage: its layer} from docs/DESIGN.md's "Layers" list."""
    text = (ROOT / "docs" / "DESIGN.md").read_text(encoding="utf-8")
    section = text.split("## Layers", 1)[1].split("\n## ", 1)[0]
    out = {}
    for number, names in re.findall(r"^(\d+)\. (.+)$", section, flags=re.M):
        for name in names.split(","):
            out[name.strip()] = int(number)
    return out


def module_name(path: Path, package: Path = PACKAGE) -> str:
    parts = list(path.relative_to(package.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def import_graph(package: Path = PACKAGE) -> dict[str, set[str]]:
    """{module: the package's modules it imports}. ``from PKG import NAME`` points at PKG.NAME when that is a
    module, else at PKG."""
    modules = {module_name(p, package): p for p in package.rglob("*.py")}
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for name, path in modules.items():
        here = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = here.split(".")[: len(here.split(".")) - node.level + 1]
                    target = ".".join(base + ([node.module] if node.module else []))
                else:
                    target = node.module or ""
                found = [f"{target}.{a.name}" if f"{target}.{a.name}" in modules else target for a in node.names]
            elif isinstance(node, ast.Import):
                found = [a.name for a in node.names]
            else:
                continue
            graph[name].update(t for t in found if t in modules and t != name)
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan's algorithm)."""
    index, low, stack, on_stack, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
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
                out.append(sorted(component))

    for v in graph:
        if v not in index:
            visit(v)
    return out


def layer_of(module: str, order: dict[str, int]) -> int:
    parts = module.split(".")
    if len(parts) == 1:
        return max(order.values()) + 1  # the package's __init__: above everything
    return order[parts[1]]


def test_every_module_has_a_layer():
    order = layers()
    assert order["errors"] == 1 and order["cli"] == max(order.values())
    missing = sorted({m.split(".")[1] for m in import_graph() if "." in m} - set(order))
    assert not missing, f"add {missing} to the Layers list in docs/DESIGN.md"


def test_no_import_cycle():
    assert cycles(import_graph()) == []


def test_no_import_points_up_a_layer():
    order = layers()
    up = [f"{a} -> {b}" for a, targets in import_graph().items() for b in targets
          if layer_of(a, order) < layer_of(b, order)]
    assert up == []


def test_the_checks_see_a_cycle_and_an_upward_import(tmp_path):
    """Negative control: a small package with a cycle and an import from a lower layer up."""
    pkg = tmp_path / "spacepol"
    (pkg / "physics").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "physics" / "__init__.py").write_text("")
    (pkg / "physics" / "a.py").write_text("from .b import x\n")
    (pkg / "physics" / "b.py").write_text("def f():\n    from .a import y\n    from ..api import run\n")
    (pkg / "api.py").write_text("RUN = 1\n")
    graph = import_graph(pkg)
    assert cycles(graph) == [["spacepol.physics.a", "spacepol.physics.b"]]
    assert "spacepol.api" in graph["spacepol.physics.b"]
    assert layer_of("spacepol.physics.b", layers()) < layer_of("spacepol.api", layers())


def private_imports(package: Path = PACKAGE) -> list[str]:
    """``from X import _name`` anywhere in the package: another module's private name."""
    out = []
    for path in package.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module != "__future__":
                out += [f"{module_name(path, package)}: {a.name}" for a in node.names
                        if a.name.startswith("_") and not a.name.startswith("__")]
    return out


def test_no_module_imports_another_modules_private_name(tmp_path):
    assert private_imports() == []
    # negative control: the check finds one where it is
    pkg = tmp_path / "spacepol"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from .b import _hidden\n")
    assert private_imports(pkg) == ["spacepol.a: _hidden"]
