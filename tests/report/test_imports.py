"""The report package imports one way: no module of it imports, directly or through other
report modules, a module that imports it back (lazy and TYPE_CHECKING imports count)."""

from __future__ import annotations

import ast
from pathlib import Path

import trackplan.report

PACKAGE = Path(trackplan.report.__file__).parent


def _imports(file: Path) -> set[str]:
    """Every ``trackplan.report.*`` module ``file`` imports, anywhere in it."""
    found = set()
    for node in ast.walk(ast.parse(file.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module:
            names = [node.module, *(f"{node.module}.{alias.name}" for alias in node.names)]
        elif isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        else:
            continue
        found |= {name for name in names if name.startswith("trackplan.report.")}
    return found


def _graph() -> dict[str, set[str]]:
    modules = {f"trackplan.report.{file.stem}": file for file in PACKAGE.glob("*.py")}
    del modules["trackplan.report.__init__"]  # the package's front door re-exports
    return {name: _imports(file) & modules.keys() for name, file in modules.items()}


def _cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import cycle of ``graph`` as a list of modules, or None."""
    done: set[str] = set()

    def visit(module: str, trail: list[str]) -> list[str] | None:
        if module in trail:
            return [*trail[trail.index(module) :], module]
        if module in done:
            return None
        for imported in sorted(graph[module]):
            if cycle := visit(imported, [*trail, module]):
                return cycle
        done.add(module)
        return None

    for module in sorted(graph):
        if cycle := visit(module, []):
            return cycle
    return None


def test_the_report_modules_import_without_cycles():
    cycle = _cycle(_graph())
    assert cycle is None, " -> ".join(cycle or [])


def test_the_cycle_finder_finds_a_planted_cycle():
    graph = _graph()
    graph["trackplan.report.figure_style"].add("trackplan.report.figures")
    assert _cycle(graph) is not None


def test_the_shared_figure_and_page_helpers_import_no_plot_or_page():
    graph = _graph()
    for low in ("trackplan.report.figure_style", "trackplan.report.page_style"):
        assert graph[low] == set(), low
    # the page markup builds on the one page style only
    assert graph["trackplan.report.html_markup"] == {"trackplan.report.page_style"}
