"""One placement for several seams: the batched fitness, an unreachable seam named, and the
shipped bracket optimised end to end, its outputs re-checked and exported."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.conftest import CASES
from tests.planning.test_cycle import CASE, X
from trackplan.cli import ExitCode, main
from trackplan.io.case_file import load_case, load_case_text
from trackplan.planning.cycle import seam_geometries
from trackplan.search.cycle_search import CycleFitness
from trackplan.search.fitness import Finding, PlacementFitness
from trackplan.search.space import SearchSpace


@pytest.fixture(scope="module")
def fitness() -> CycleFitness:
    case = load_case_text(yaml.safe_dump(CASE, sort_keys=False))
    space = SearchSpace.from_bounds(case.bounds, case.source)
    return CycleFitness(case, space, seam_geometries(case), "smooth")


@pytest.fixture(scope="module")
def batch() -> np.ndarray:
    rng = np.random.default_rng(7)
    near = X + rng.normal(0.0, [0.05, 0.05, 0.02, 0.05, 0.05, 0.3], size=(9, 6))
    return np.vstack([X, near, [0.5, 0.5, 0.5, 0.0, 0.0, 0.0], [2.0, 0.0, 0.0, 0.0, 0.0, 0.0]])


def test_the_batch_is_the_loop_of_singles(fitness: CycleFitness, batch: np.ndarray) -> None:
    together = fitness.evaluate(batch)
    alone = [fitness.evaluate(row[None]) for row in batch]
    assert np.array_equal(together.feasible, [a.feasible[0] for a in alone])
    assert np.allclose(together.fitness, [a.fitness[0] for a in alone], rtol=1e-12, atol=0.0)
    assert together.feasible[0] and not together.feasible[-1]
    assert together.finding[-1] == Finding.REACH


def test_feasible_only_when_every_seam_is(fitness: CycleFitness, batch: np.ndarray) -> None:
    together = fitness.evaluate(batch)
    each = [
        PlacementFitness(
            fitness.case.seam_case(i),
            fitness.space,
            seam.geometry,
            "smooth",
            n_poses=len(seam.s_grid),
        ).evaluate(batch)
        for i, seam in enumerate(fitness.seams)
    ]
    every = np.all([screen.feasible for screen in each], axis=0)
    assert np.array_equal(together.feasible, every)
    assert 0 < every.sum() < len(batch)  # the batch has both kinds
    # a feasible cycle costs at least the sum of its seams' J
    J = np.sum([screen.objective for screen in each], axis=0)
    assert np.all(together.fitness[every] >= J[every] - 1e-12)


def test_a_seam_unreachable_everywhere_makes_optimize_exit_3_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = copy.deepcopy(CASE)
    data["paths"].append(
        {"name": "far-away", "start": [2.5, 0, 0], "segments": [{"line": {"to": [2.6, 0, 0]}}]}
    )
    data["placement"] = {"x": [0.1, 0.6], "y": [-0.5, 0.5], "z": [-0.3, -0.28], "reach": [0.2, 0.8]}
    file = tmp_path / "far.yaml"
    file.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    code = main(
        ["optimize", str(file), "--out", str(tmp_path / "run"), "--budget", "60", "--no-report"]
    )
    out = capsys.readouterr().out
    assert code == ExitCode.INFEASIBLE
    assert "seam far-away is feasible at none of the 60 placements evaluated" in out
    result = json.loads((tmp_path / "run" / "result.json").read_text(encoding="utf-8"))
    assert result["optimizer"]["unreachable_seams"] == ["far-away"]
    assert result["feasible"] is False


@pytest.mark.slow
def test_the_shipped_bracket_optimizes_rechecks_and_exports(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    case_file = CASES / "bracket-4-fillets.yaml"
    run = tmp_path / "run"
    assert main(["optimize", str(case_file), "--out", str(run)]) == ExitCode.OK
    out = capsys.readouterr().out
    assert "feasible placement for all 4 seams" in out
    result = json.loads((run / "result.json").read_text(encoding="utf-8"))
    case = load_case(case_file)
    assert result["feasible"] and {s["name"] for s in result["seams"]} == set(case.cycle.names)
    assert result["cycle_time"] == pytest.approx(result["seam_time"] + result["air_time"])
    assert result["sequence_exact"] is True and len(result["sequence"]) == 4
    assert all(s["max_tracking_error"] <= case.task.tolerance for s in result["seams"])
    assert result["min_clearance"]["distance"] >= case.cell.clearance
    header = (run / "trajectory.csv").read_text(encoding="utf-8").splitlines()[0]
    assert header.endswith(",spin,segment")
    assert (run / "cycle.png").is_file() and (run / "report.html").is_file()
    placement = [str(result["placement"][k]) for k in ("x", "y", "z", "roll", "pitch", "yaw")]
    assert main(["check", str(case_file), str(run), "--placement", *placement]) == ExitCode.OK
    assert "feasible" in capsys.readouterr().out
    ros = tmp_path / "cycle.ros.yaml"
    assert main(["export", str(run), "--format", "ros", "--output", str(ros)]) == ExitCode.OK
    message = yaml.safe_load(ros.read_text(encoding="utf-8"))
    assert len(message["points"]) == result["n_samples"]
