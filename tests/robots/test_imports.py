"""The robots package imports one way: no cycle among its modules and nothing above it.

Every import counts, at module level, inside functions and under ``TYPE_CHECKING``
(docs/architecture.md: a lower layer never imports a higher one, not even lazily).
"""

from __future__ import annotations

import ast
from pathlib import Path

import trackplan

PACKAGE = Path(trackplan.__file__).parent
ROBOTS = PACKAGE / "robots"
BELOW = {
    "trackplan",
    "trackplan._kernels",
    "trackplan.errors",
    "trackplan.status",
    "trackplan.choices",
    "trackplan.frames",
    "trackplan.stencils",
    "trackplan.derivatives",
    "trackplan.derived",
}
"""The modules below the robots layer that it may import."""


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set[str]:
    """Every ``trackplan`` module a file imports, anywhere in it (``from package import
    submodule`` counts as the submodule)."""
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.startswith("trackplan"))
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module.startswith("trackplan"):
                for alias in node.names:
                    sub = f"{node.module}.{alias.name}"
                    is_module = (PACKAGE.parent / sub.replace(".", "/")).with_suffix(".py")
                    found.add(sub if is_module.exists() else node.module)
    return found


def _graph() -> dict[str, set[str]]:
    return {_module_name(p): _imports(p) for p in sorted(ROBOTS.rglob("*.py"))}


def test_robots_imports_nothing_above_it():
    upward = {
        (module, target)
        for module, targets in _graph().items()
        for target in targets
        if not target.startswith("trackplan.robots") and target not in BELOW
    }
    assert not upward


def test_robots_modules_import_without_a_cycle():
    graph = _graph()
    internal = {m: {t for t in ts if t in graph} for m, ts in graph.items()}
    state: dict[str, int] = {}  # 1 on the stack, 2 done
    cycles: list[list[str]] = []

    def visit(module: str, stack: list[str]) -> None:
        state[module] = 1
        for target in sorted(internal[module]):
            if state.get(target) == 1:
                cycles.append([*stack[stack.index(target) :], target])
            elif target not in state:
                visit(target, [*stack, target])
        state[module] = 2

    for module in sorted(internal):
        if module not in state:
            visit(module, [module])
    assert not cycles
