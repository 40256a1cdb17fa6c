"""One placement for several seams: the batched fitness, each seam's spin in the decision
vector, an unreachable seam named, a circle that only a spun tool welds, and the shipped
bracket optimised end to end, its outputs re-checked and exported."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from tests.conftest import CASES
from tests.planning.test_cycle import CASE, X, spun_case
from trackplan.cli import ExitCode, main
from trackplan.io.case_file import load_case, load_case_text
from trackplan.planning.seams import seam_geometries
from trackplan.search.case_fitness import CaseFitness
from trackplan.search.fitness import PlacementFitness
from trackplan.search.screening import code, outcome
from trackplan.search.space import SearchSpace
from trackplan.status import Status


@pytest.fixture(scope="module")
def fitness() -> CaseFitness:
    case = load_case_text(yaml.safe_dump(CASE, sort_keys=False))
    space = SearchSpace.from_bounds(case.bounds, case.source)
    return CaseFitness(case, space, seam_geometries(case), "smooth")


@pytest.fixture(scope="module")
def batch() -> np.ndarray:
    rng = np.random.default_rng(7)
    near = X + rng.normal(0.0, [0.05, 0.05, 0.02, 0.05, 0.05, 0.3], size=(9, 6))
    return np.vstack([X, near, [0.5, 0.5, 0.5, 0.0, 0.0, 0.0], [2.0, 0.0, 0.0, 0.0, 0.0, 0.0]])


def test_the_batch_is_the_loop_of_singles(fitness: CaseFitness, batch: np.ndarray) -> None:
    together = fitness.evaluate(batch)
    alone = [fitness.evaluate(row[None]) for row in batch]
    assert np.array_equal(together.feasible, [a.feasible[0] for a in alone])
    assert np.allclose(together.fitness, [a.fitness[0] for a in alone], rtol=1e-12, atol=0.0)
    assert together.feasible[0] and not together.feasible[-1]
    assert together.finding[-1] == code(Status.REACH)


def test_feasible_only_when_every_seam_is(fitness: CaseFitness, batch: np.ndarray) -> None:
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
    # the placement's variables on a bound of the box (z's range is 2 cm wide)
    X = [result["placement"][k] for k in ("x", "y", "z", "roll", "pitch", "yaw")]
    hits = SearchSpace.from_case(load_case(file)).bound_hits(np.array(X))
    assert result["optimizer"]["on_bounds"] == [hit.as_dict() for hit in hits]
    assert ("note: the placement lies on a bound" in out) == bool(hits)


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
    assert result["feasible"] and {s["name"] for s in result["seams"]} == {
        seam.name for seam in case.seams
    }
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


@pytest.fixture(scope="module")
def spun() -> CaseFitness:
    """Seam ``left`` with ``spin: free``, ``corner`` fixed."""
    case = spun_case({"spin": "free", "spin_range": [-np.pi, np.pi]}, {})
    return CaseFitness(case, SearchSpace.from_case(case), seam_geometries(case), "smooth")


def test_the_vector_is_the_placement_then_each_free_seams_spin(spun: CaseFitness) -> None:
    space = spun.space
    assert space.n_var == 6 + 1
    assert space.lower[6] == -np.pi and space.upper[6] == np.pi and space.anchor[6] == 0.0
    assert spun.slices == (slice(6, 7), slice(7, 7))
    fixed = load_case_text(yaml.safe_dump(CASE))
    assert SearchSpace.from_case(fixed).n_var == 6  # fixed spins add none
    candidate = np.r_[X, 0.7]
    assert spun.seam_spins(candidate)[0].tolist() == [0.7] and spun.seam_spins(candidate)[1] is None


def test_each_seam_is_screened_with_its_own_spin(spun: CaseFitness, batch: np.ndarray) -> None:
    rng = np.random.default_rng(3)
    spins = np.r_[np.linspace(-np.pi, np.pi, 9), rng.uniform(-np.pi, np.pi, len(batch) - 9)]
    candidates = np.vstack(
        [np.column_stack([np.tile(X, (9, 1)), spins[:9]]), np.column_stack([batch[9:], spins[9:]])]
    )
    screen = spun.screen_seams(candidates)
    for i, seam in enumerate(spun.seams):
        space = SearchSpace.from_case(seam.case)
        alone = PlacementFitness(
            seam.case, space, seam.geometry, "smooth", n_poses=len(seam.s_grid)
        ).evaluate(np.hstack([candidates[:, :6], candidates[:, spun.slices[i]]]))
        assert np.array_equal(screen.ok[i], alone.feasible)
        assert np.allclose(screen.objective[i][alone.feasible], alone.objective[alone.feasible])
    # at one placement the free seam's reach and start follow its spin; the fixed seam's not
    assert 0 < screen.ok[0, :9].sum() < 9
    assert np.ptp(screen.q_first[0, :9][screen.ok[0, :9]], axis=0).max() > 1.0
    assert screen.ok[1, :9].all() and np.ptp(screen.q_first[1, :9], axis=0).max() == 0.0
    # the placement alone: the spin in the middle of its range
    middle = spun.evaluate(np.r_[X, 0.0][None])
    assert spun.evaluate(X[None]).fitness[0] == middle.fitness[0]


CIRCLE_TOOL = {"frame": "seam", "normal": [0, -1, 0], "work_angle": 0.0, "travel_angle": 0.0}


def circle_and_line(spin: str) -> dict:
    """The paper's circle with the seam frame (``cases/paper-circle-seam-free.yaml``) beside a
    short line, the circle's spin ``spin``."""
    circle = load_case(CASES / "paper-circle-seam-free.yaml")
    assert circle.task.tool.spin == "free-varying"
    data = yaml.safe_load((CASES / "paper-circle-seam-free.yaml").read_text(encoding="utf-8"))
    path, task = data.pop("path"), data.pop("task")
    task["sample_time"] = 0.004
    data["name"] = "circle-and-line"
    data["paths"] = [
        {"name": "circle", **path, "task": {"tool": {**task["tool"], "spin": spin}}},
        {"name": "line", "start": [0.05, 0, 0], "segments": [{"line": {"to": [0.1, 0, 0]}}]},
    ]
    data["task"] = {**task, "tool": {**CIRCLE_TOOL, "spin": "fixed"}}
    data["approach"] = 0.02
    data["placement"].pop("example")
    return data


@pytest.mark.slow
def test_only_a_spun_circle_beside_a_line_is_feasible(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    runs = {}
    for spin in ("free-varying", "fixed"):
        file = tmp_path / f"{spin}.yaml"
        file.write_text(yaml.safe_dump(circle_and_line(spin), sort_keys=False), encoding="utf-8")
        run = tmp_path / spin
        options = ["--budget", "600", "--restarts", "1", "--no-report"]
        runs[spin] = main(["optimize", str(file), "--out", str(run), *options])
    out = capsys.readouterr().out
    assert runs == {"free-varying": ExitCode.OK, "fixed": ExitCode.INFEASIBLE}
    assert "seam circle is feasible at none of the 600 placements evaluated" in out
    assert "the tool turns 6.283 rad (1.00 turns) about its own axis" in out
    run = tmp_path / "free-varying"
    result = json.loads((run / "result.json").read_text(encoding="utf-8"))
    seams = {seam["name"]: seam for seam in result["seams"]}
    coefficients = seams["circle"]["spin"]["coefficients"]
    assert len(coefficients) == 6 and np.ptp(coefficients) > 1.0  # it counter-rotates
    assert seams["line"]["spin"] == {"value": 0.0}
    # the chosen profile is what the circle's samples of trajectory.csv carry: it ends at
    # its last coefficient (clamped spline)
    lines = (run / "trajectory.csv").read_text(encoding="utf-8").splitlines()
    header = lines[0].split(",")
    rows = [line.split(",") for line in lines[1:]]
    spin = np.array([float(r[header.index("spin")]) for r in rows if r[-1] == "circle"])
    assert spin[-1] == pytest.approx(coefficients[-1], abs=1e-9)
    assert spin.min() >= -np.pi and spin.max() <= np.pi and np.ptp(spin) > 1.0
    placement = [str(result["placement"][k]) for k in ("x", "y", "z", "roll", "pitch", "yaw")]
    file = tmp_path / "free-varying.yaml"
    assert main(["check", str(file), str(run), "--placement", *placement]) == ExitCode.OK


def test_a_case_of_one_seam_is_the_same_fitness_with_no_move() -> None:
    """One mechanism: the case fitness of a single-path case is its seam's screening, the
    moves between seams adding nothing (one seam, no home)."""
    case = load_case(CASES / "paper-corner.yaml")
    space = SearchSpace.from_case(case)
    geometries = seam_geometries(case)
    whole = CaseFitness(case, space, geometries, "smooth")
    seam = PlacementFitness(case, space, geometries[0, False], "smooth")
    rng = np.random.default_rng(3)
    batch = np.vstack([space.sample(rng, 40), [[2.0, 0.0, 0.0, 0.0, 0.0, 0.0]]])
    together, alone = whole.evaluate(batch), seam.evaluate(batch)
    assert together.feasible.any() and not together.feasible.all()
    assert np.array_equal(together.feasible, alone.feasible)
    assert np.array_equal(together.finding, alone.finding)
    assert np.allclose(together.fitness, alone.fitness, rtol=1e-12, atol=0.0)
    screens = whole.screen_seams(batch[together.feasible])
    assert np.all(whole.air_costs(screens, np.ones(int(together.feasible.sum()), bool)) == 0.0)
    assert outcome(together.finding[-1]) is Status.REACH
