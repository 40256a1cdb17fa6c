"""``trackplan map --points``: a grid too fine for bounded time and memory is one line, exit 2."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.conftest import CASES
from trackplan.cli import main
from trackplan.errors import CaseError
from trackplan.io.case_file import load_case
from trackplan.search import placement_map as placement_map_module
from trackplan.search.placement_map import MAX_MAP_POINTS, placement_map

CASE = CASES / "paper-corner.yaml"


def _map(tmp_path: Path, points: int) -> list[str]:
    return [
        "map",
        str(CASE),
        "--rpy",
        "0",
        "0",
        "0",
        "--z",
        "0",
        "--points",
        str(points),
        "--out",
        str(tmp_path / "map"),
    ]


def _never(*args: object, **kwargs: object) -> None:
    raise AssertionError("the map was computed")


@pytest.mark.parametrize("points", [MAX_MAP_POINTS + 1, 100_000, 10**9])
def test_a_grid_over_the_limit_is_refused_before_any_work(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    points: int,
) -> None:
    # 100,000 points tried to allocate 74.5 GiB (exit 1); screening 10^10 placements would
    # take weeks anyway
    monkeypatch.setattr(placement_map_module, "placement_map", _never)
    monkeypatch.setattr("trackplan.io.case_file.load_case", _never)
    code = main(_map(tmp_path, points))
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1
    assert err.startswith(f"--points: expected at most {MAX_MAP_POINTS} grid points")
    assert f"got {points}" in err
    assert not (tmp_path / "map").exists()


def test_the_limit_is_where_it_says(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(placement_map_module, "MAX_MAP_POINTS", 5)
    assert main(_map(tmp_path, 5)) == 0
    assert "of 5 x 5 placements" in capsys.readouterr().out
    assert main(_map(tmp_path, 6)) == 2
    assert "--points: expected at most 5 grid points" in capsys.readouterr().err


def test_the_api_refuses_it_too() -> None:
    case = load_case(CASE)
    with pytest.raises(CaseError, match=f"expected at most {MAX_MAP_POINTS} grid points"):
        placement_map(case, [0, 0, 0, 0, 0, 0], n_points=MAX_MAP_POINTS + 1)


def test_every_outcome_of_the_screening_has_a_map_class(monkeypatch: pytest.MonkeyPatch) -> None:
    """A placement too heavy to hold (Status.HOLDING_TORQUE) is a map point like any other:
    the map classes cover every outcome code of the screening, not a hand-picked few."""
    import numpy as np

    from trackplan.search.fitness import PlacementFitness
    from trackplan.search.screening import code
    from trackplan.status import Status

    evaluate = PlacementFitness.evaluate

    def heavy(self: PlacementFitness, X: np.ndarray, incumbent: float = np.inf):  # type: ignore[no-untyped-def]
        screening = evaluate(self, X, incumbent)
        screening.finding[:] = code(Status.HOLDING_TORQUE)
        return screening

    monkeypatch.setattr(PlacementFitness, "evaluate", heavy)
    result = placement_map(load_case(CASE), np.zeros(6), n_points=3)
    assert (result.reason == placement_map_module.REASONS.index("joint limit")).all()
