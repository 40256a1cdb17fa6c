"""Start-up: each command imports what it uses (docs/benchmarks.md, "Wall time").

Each check runs in a fresh interpreter, the only way to see what an import pulls in.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from tests.conftest import CASES
from trackplan.forking import can_fork

SCIPY_SOLVERS = ("scipy.optimize", "scipy.interpolate", "scipy.spatial", "scipy.stats")
"""scipy's optimisers, splines and trees: a plan whose speed stays in windows uses none."""

REPORT_AND_OPTIONAL = (
    "matplotlib",
    "plotly",
    "dask",
    "distributed",
    "trimesh",
    "yourdfpy",
    "coal",
    "cma",
    "toppra",
    "ruckig",
    "pymoo.algorithms",
    "pymoo.core.algorithm",
    "pymoo.core.evaluator",
    "pymoo.termination",
    "rich.progress",
    "rich.table",
    "trackplan.report",
    "trackplan.search.operators",
    "trackplan.search.pymoo_algorithms",
    "trackplan.cell.screening",
)
"""Modules a search with the default method and ``--no-report`` does not use (rich's
progress bar only on a terminal, its tables only for the commands that print one; the
cell's compiled screening only for a case with a cell; pymoo's Algorithm, evaluator and
terminations only for the methods that run as a pymoo Algorithm)."""


def _loaded_after(code: str, modules: tuple[str, ...]) -> list[str]:
    """Which of ``modules`` (or their submodules) are imported after running ``code``."""
    probe = (
        f"{code}\nimport json, sys\n"
        f"print(json.dumps([m for m in {list(modules)!r} "
        "if any(k == m or k.startswith(m + '.') for k in sys.modules)]))"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.splitlines()[-1])


def test_the_command_line_imports_no_planner_before_a_command_runs():
    """``trackplan --help`` and usage errors need typer only: no numpy, numba or pydantic."""
    heavy = ("numpy", "numba", "pydantic", "scipy", "pymoo", "trackplan.case", "trackplan.io")
    assert _loaded_after("import trackplan.cli.app", heavy) == []


def test_import_trackplan_is_cheap():
    assert _loaded_after("import trackplan", ("numpy", "importlib.metadata")) == []


def test_plan_in_windows_imports_no_scipy_solver(tmp_path):
    """A plan of the corner case at its example placement (a blend: the scalar solvers run;
    the speed stays in windows) imports none of scipy's optimisers, splines or trees."""
    run = (
        "from trackplan.cli import main\n"
        f"code = main(['plan', {str(CASES / 'paper-corner.yaml')!r}, '--no-report', "
        f"'--out', {str(tmp_path / 'out')!r}])\n"
        "assert code == 0, code"
    )
    assert _loaded_after(run, SCIPY_SOLVERS) == []


def test_optimize_without_report_imports_only_what_it_uses(tmp_path):
    """A whole ``optimize --no-report`` of the corner case imports neither the report, the
    cell's exact distances, Dask, the URDF stack nor the population methods."""
    run = (
        "from trackplan.cli import main\n"
        f"code = main(['optimize', {str(CASES / 'paper-corner.yaml')!r}, '--no-report', "
        f"'--budget', '30', '--out', {str(tmp_path / 'out')!r}])\n"
        "assert code == 0, code"
    )
    # rich before 15.0 imports its tables with rich.console, which every command prints with
    its_own = _loaded_after("import rich.console", REPORT_AND_OPTIONAL)
    assert [m for m in _loaded_after(run, REPORT_AND_OPTIONAL) if m not in its_own] == []


def test_input_schemas_are_built_when_a_file_is_validated():
    """Importing the file loaders builds no pydantic schema (``defer_build``); loading the
    corner case builds the one it validates, not the cell, robot-file or tool schemas."""
    probe = (
        "import json, pydantic\n"
        "from trackplan.io import case_file, case_schema, cell_file, robot_file, robot_schema\n"
        "from trackplan.io import tool_file\n"
        "modules = (case_file, case_schema, cell_file, robot_file, robot_schema, tool_file)\n"
        "models = [m for mod in modules for m in vars(mod).values() if isinstance(m, type)\n"
        "          and issubclass(m, pydantic.BaseModel) and m.__module__ == mod.__name__]\n"
        "def built():\n"
        "    return [m.__name__ for m in models if m.__pydantic_complete__]\n"
        "imported = built()\n"
        f"case_file.load_case({str(CASES / 'paper-corner.yaml')!r})\n"
        "print(json.dumps([len(models), imported, built()]))"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    n_models, imported, loaded = json.loads(out.stdout.splitlines()[-1])
    assert n_models > 20
    assert imported == []
    assert loaded == ["SinglePathCaseModel"]


@pytest.mark.skipif(not can_fork(), reason="no second core or no fork here")
def test_optimize_plans_beside_the_search(tmp_path):
    """With a second core, the plans at full Ts (the before plan at the centre of the box runs
    the continuous speed curve: scipy's LP solver and splines) are made in the process forked
    at the search's start: the searching process imports none of scipy's solvers."""
    run = (
        "from trackplan.cli import main\n"
        f"code = main(['optimize', {str(CASES / 'paper-corner.yaml')!r}, '--no-report', "
        f"'--budget', '30', '--out', {str(tmp_path / 'out')!r}])\n"
        "assert code == 0, code"
    )
    assert _loaded_after(run, SCIPY_SOLVERS) == []


def test_the_command_exits_with_its_code_after_the_exit_handlers(tmp_path):
    """``run_and_exit`` (the ``trackplan`` command) skips the interpreter's teardown but
    still runs the atexit handlers, flushes what was printed and exits with the command's
    code: 0 for a valid case, 2 for a missing file."""
    probe = (
        "import atexit, sys\n"
        "atexit.register(print, 'exit handler ran')\n"
        "sys.argv = ['trackplan', 'validate', sys.argv[1]]\n"
        "from trackplan.cli import run_and_exit\n"
        "run_and_exit()\n"
    )
    for case, code in ((CASES / "paper-corner.yaml", 0), (tmp_path / "missing.yaml", 2)):
        done = subprocess.run(
            [sys.executable, "-c", probe, str(case)], capture_output=True, text=True
        )
        assert done.returncode == code, done.stderr
        lines = done.stdout.splitlines()
        assert lines[-1] == "exit handler ran"
        if code == 0:
            assert any("paper-corner" in line for line in lines[:-1]), done.stdout
        else:
            assert len(done.stderr.splitlines()) == 1 and "missing.yaml" in done.stderr
