"""The case's path built once: from a case or from plain data, and paths/ imports downward only."""

from __future__ import annotations

import ast
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from trackplan.io.case_file import load_case
from trackplan.paths import ArcSpec, LineSpec
from trackplan.paths.path_geometry import PathGeometry

CASES = Path(__file__).parents[2] / "cases"
PATHS = Path(__file__).parents[2] / "trackplan" / "paths"
BELOW_PATHS = ("trackplan.paths", "trackplan.errors", "trackplan.frames", "trackplan._kernels")
"""The trackplan modules paths/ may import: itself and the layers below it."""


def _trackplan_imports(source: Path) -> list[str]:
    """Every ``trackplan.*`` module a file imports, under TYPE_CHECKING or in a function too."""
    names = []
    for node in ast.walk(ast.parse(source.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module:
            names.append(node.module)
        elif isinstance(node, ast.Import):
            names.extend(alias.name for alias in node.names)
    return [name for name in names if name.split(".")[0] == "trackplan"]


def test_paths_import_nothing_above_them():
    upward = {
        f"{source.name}: {name}"
        for source in sorted(PATHS.glob("*.py"))
        for name in _trackplan_imports(source)
        if not name.startswith(BELOW_PATHS)
    }
    assert not upward


def test_from_case_equals_build_from_the_case_data():
    case = load_case(CASES / "paper-corner.yaml")
    from_case = PathGeometry.from_case(case)
    built = PathGeometry.build(case.start, case.segments, case.task.tolerance)
    assert built.mode == from_case.mode == "g2"
    assert built.planned.length == from_case.planned.length
    s = np.linspace(0.0, built.planned.length, 101)
    np.testing.assert_allclose(
        built.planned.sample(s).position, from_case.planned.sample(s).position, atol=1e-12
    )


def test_from_case_reads_any_object_with_start_segments_and_tolerance():
    source = SimpleNamespace(
        start=np.zeros(3),
        segments=(
            LineSpec(to=np.array([0.2, 0.0, 0.0])),
            ArcSpec(np.array([0.2, 0.1, 0.0]), np.array([0.0, 0.0, 1.0]), np.pi / 2),
        ),
        task=SimpleNamespace(tolerance=1e-3),
    )
    geometry = PathGeometry.from_case(source, "paper")
    assert geometry.mode == "paper"
    # a line of 0.2 m and a quarter circle of radius 0.1 m, tangent at the junction: no corner
    np.testing.assert_allclose(geometry.nominal.length, 0.2 + 0.05 * np.pi, rtol=1e-12)
    np.testing.assert_allclose(geometry.planned.length, geometry.nominal.length, rtol=1e-12)
