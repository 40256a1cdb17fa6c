"""Case files with several seams (``paths:``): what they load into, and every bad input one
clear line from ``trackplan validate`` with exit code 2."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from tests.conftest import CASES
from tests.io.test_case_file import validate_fails
from trackplan.io.case_file import load_case, load_case_text

SEAMS: dict[str, Any] = {
    "name": "two-seams",
    "robot": "puma560",
    "paths": [
        {"name": "a", "start": [0, 0, 0], "segments": [{"line": {"to": [0.1, 0, 0]}}]},
        {
            "name": "b",
            "start": [0, 0.05, 0],
            "segments": [{"line": {"to": [0.1, 0.05, 0]}}],
            "task": {"rated_speed": 0.01, "tool_rpy": [3.0, 0, 0]},
            "reversible": False,
        },
    ],
    "approach": 0.02,
    "task": {"rated_speed": 0.02, "corner_speed": 0.015, "tool_rpy": [3.141592653589793, 0, 0]},
}


def write(folder: Path, data: dict[str, Any]) -> Path:
    file = folder / "seams.yaml"
    file.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return file


def test_paths_load_into_a_cycle_with_per_seam_tasks() -> None:
    case = load_case_text(yaml.safe_dump(SEAMS, sort_keys=False))
    assert case.seam_names == ("a", "b")
    sequencing = case.sequencing
    assert (sequencing.sequence, sequencing.approach, sequencing.home) == ("optimize", 0.02, None)
    a, b = case.seams
    assert (a.task.rated_speed, b.task.rated_speed) == (0.02, 0.01)
    assert (a.task.corner_speed, b.task.corner_speed) == (0.015, 0.015)
    assert np.allclose(b.task.tool.rpy, [3.0, 0, 0]) and np.allclose(a.task.tool.rpy, [np.pi, 0, 0])
    assert (a.reversible, b.reversible) == (True, False)
    # the case's own path and task are the first seam's; seam_case gives each seam's
    assert case.start is a.start and case.task is a.task
    single = case.seam_case(1)
    assert (single.name, len(single.seams), single.task.rated_speed) == ("b", 1, 0.01)
    assert np.allclose(single.start, [0, 0.05, 0])


def test_a_single_path_case_is_one_seam_without_cycle() -> None:
    case = load_case(CASES / "bracket-weld.yaml")
    assert case.seam_names == (case.name,)
    assert (case.sequencing.sequence, case.sequencing.approach) == ("given", 0.0)
    assert len(case.seams) == 1 and case.seam_case(0) is case


def test_the_shipped_case_has_four_seams_and_a_closed_loop() -> None:
    case = load_case(CASES / "bracket-4-fillets.yaml")
    assert len(case.seams) == 4
    assert case.sequencing.sequence == "optimize" and case.cell is not None
    boss = case.seams[case.seam_names.index("boss")]
    assert abs(abs(boss.segments[0].angle) - 2 * np.pi) < 1e-12  # closed loop


@pytest.mark.parametrize(
    ("change", "line"),
    [
        (
            {"paths.1.name": "a"},
            "paths[1].name: seam name 'a' is used twice (also paths[0].name); give each seam "
            "its own name",
        ),
        ({"approach": -0.01}, "approach: expected a number ≥ 0, got -0.01"),
        (
            {"home": [0, 0, 0, 0, 0]},
            "home: expected 6 joint values (one per joint of puma560), rad, got 5: "
            "[0.0, 0.0, 0.0, 0.0, 0.0]",
        ),
        (
            {"home": [0, 0, 3.0, 0, 0, 0]},
            "home[2]: joint 3 at 3 rad is outside its limits [-2.35619, 2.35619] rad",
        ),
        (
            {"path": {"start": [0, 0, 0], "segments": [{"line": {"to": [0.1, 0, 0]}}]}},
            "paths: give path (one seam) or paths (several named seams), not both; move path "
            "into paths as one named entry",
        ),
        (
            {"sequence": "shortest"},
            "sequence: expected one of 'optimize' or 'given', got 'shortest'",
        ),
        (
            {"paths.0.segments": [{"line": {"to": [0, 0, 0]}}]},
            "paths[0].segments[0].line.to: ",
        ),
        ({"paths.1.task.speed": 0.1}, "paths[1].task.speed: unknown key"),
        (
            {"objective": {"kind": "time"}},
            "objective.kind: kind time is not supported with several seams (paths): they "
            "minimise travel (Eq. 8) with objective.time_weight on the cycle time",
        ),
    ],
)
def test_bad_input_is_one_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, change: dict[str, Any], line: str
) -> None:
    data = copy.deepcopy(SEAMS)
    for key, value in change.items():
        *parents, last = key.split(".")
        node: Any = data
        for parent in parents:
            node = node[int(parent)] if isinstance(node, list) else node[parent]
        node[last] = value
    file = write(tmp_path, data)
    assert validate_fails(capsys, str(file)).startswith(f"{file}: {line}")


@pytest.mark.parametrize("key", ["sequence", "approach", "home"])
def test_cycle_keys_need_paths(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, key: str
) -> None:
    data = copy.deepcopy(SEAMS)
    data["path"] = data.pop("paths")[0]
    del data["path"]["name"]
    data.pop("approach")
    data[key] = {"sequence": "given", "approach": 0.01, "home": [0] * 6}[key]
    file = write(tmp_path, data)
    assert validate_fails(capsys, str(file)) == (
        f"{file}: {key}: {key} is only used with paths (several seams)"
    )


@pytest.mark.parametrize(
    ("name", "shown"),
    [
        ("left,right", "'left,right'"),
        ('say "a"', "'say \"a\"'"),
        ("two\nlines", "'two\\nlines'"),
        ("tab\there", "'tab\\there'"),
        ("=HYPERLINK(1)", "'=HYPERLINK(1)'"),
        ("+1", "'+1'"),
        ("-fillet", "'-fillet'"),
        ("@SUM", "'@SUM'"),
    ],
)
def test_a_seam_name_that_would_break_trajectory_csv_is_refused(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, name: str, shown: str
) -> None:
    # seam names label trajectory.csv's segment column, written as they are
    data = copy.deepcopy(SEAMS)
    data["paths"][1]["name"] = name
    file = write(tmp_path, data)
    line = validate_fails(capsys, str(file))
    assert line.startswith(f"{file}: paths[1].name: a seam name labels the rows of ")
    assert line.endswith(f", got {shown}")


def test_seam_names_with_spaces_and_digits_load(tmp_path: Path) -> None:
    data = copy.deepcopy(SEAMS)
    data["paths"][0]["name"] = "fillet 1 (left)"
    data["paths"][1]["name"] = "2nd_seam.b"
    case = load_case(write(tmp_path, data))
    assert [seam.name for seam in case.seams] == ["fillet 1 (left)", "2nd_seam.b"]
