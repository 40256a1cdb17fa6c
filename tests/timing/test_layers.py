"""The time laws sit below the case: nothing in timing/ (nor the modules it reads) imports up."""

from __future__ import annotations

import ast

import pytest

from tests.conftest import REPO

ABOVE_TIMING = (
    "trackplan.case",
    "trackplan.io",
    "trackplan.cell",
    "trackplan.planning",
    "trackplan.search",
    "trackplan.study",
    "trackplan.outputs",
    "trackplan.report",
    "trackplan.cli",
)
"""Modules above the time laws in the data flow (``docs/architecture.md``)."""

MODULES = [
    *sorted((REPO / "trackplan" / "timing").glob("*.py")),
    REPO / "trackplan" / "motion.py",
    REPO / "trackplan" / "task.py",
]


def imported_modules(tree: ast.AST) -> list[str]:
    """Every module an ``import`` or ``from ... import`` names, at any depth of the tree
    (inside functions and ``TYPE_CHECKING`` blocks too)."""
    names: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            names.append(node.module)
        elif isinstance(node, ast.Import):
            names.extend(alias.name for alias in node.names)
    return names


@pytest.mark.parametrize("module", MODULES, ids=lambda path: path.name)
def test_a_time_law_module_imports_nothing_above_it(module):
    upward = [
        name
        for name in imported_modules(ast.parse(module.read_text()))
        if any(name == top or name.startswith(top + ".") for top in ABOVE_TIMING)
    ]
    assert upward == [], f"{module.relative_to(REPO)} imports {upward} (a layer above timing)"


def test_the_task_is_the_one_the_case_holds():
    from trackplan.case import Task as CaseTask
    from trackplan.task import Task

    assert CaseTask is Task


def test_one_name_per_concept_the_law_and_what_it_gives():
    from trackplan import timing
    from trackplan.choices import Timing

    law = timing.time_law("smooth")
    assert isinstance(law, timing.TimeLaw)
    assert law.timing is Timing.SMOOTH and callable(law.plan)
    assert timing.TimedPath is not timing.TimeLaw


@pytest.mark.parametrize(
    ("module", "old", "new"),
    [
        ("trackplan.timing", "TimeLawSpec", "TimeLaw"),
        ("trackplan.motion", "SampledMotion", "JointSamples"),
    ],
)
def test_an_old_name_still_imports_with_a_deprecation_warning(module, old, new):
    import importlib

    imported = importlib.import_module(module)
    with pytest.warns(DeprecationWarning, match=new):
        found = getattr(imported, old)
    assert found is getattr(imported, new)
    with pytest.raises(AttributeError):
        _ = imported.NoSuchName
