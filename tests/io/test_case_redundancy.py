"""task.redundancy in case files and ik: in robot files."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from tests.io.test_case_file import validate_fails, write_case
from trackplan.cli import main
from trackplan.io.case_file import load_case
from trackplan.redundancy import RedundancyMode, RedundancySpec

TILTED7 = Path(__file__).resolve().parent / "data" / "tilted7.urdf"


def test_the_default_steering_is_a_free_varying_profile_in_the_natural_range(tmp_path):
    case = load_case(write_case(tmp_path))
    assert case.task.redundancy == RedundancySpec()
    assert case.task.redundancy.mode is RedundancyMode.FREE_VARYING


def test_a_case_steers_the_redundancy(tmp_path):
    steering = {"mode": "free", "range": [-1.0, 0.5], "rate": 4.0}
    case = load_case(write_case(tmp_path, {"task.redundancy": steering}))
    assert case.task.redundancy == RedundancySpec(RedundancyMode.FREE, None, (-1.0, 0.5), 4.0)


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        ({"mode": "sometimes"}, "task.redundancy.mode"),
        ({"range": [1.0, -1.0]}, "min < max"),
        ({"rate": 0}, "task.redundancy.rate"),
        ({"turns": 3}, "task.redundancy.turns"),
    ],
)
def test_bad_steering_is_one_line_naming_the_key(tmp_path, capsys, value, expected):
    line = validate_fails(capsys, str(write_case(tmp_path, {"task.redundancy": value})))
    assert expected in line


def _robot_file(tmp_path: Path, ik: str) -> Path:
    file = tmp_path / "arm7.yaml"
    file.write_text(f"name: arm7\nurdf: {TILTED7}\nik: {ik}\n", encoding="utf-8")
    return file


def test_an_ik_block_chooses_the_free_joint(tmp_path, capsys):
    file = _robot_file(tmp_path, "{family: numeric, free_joint: 5}")
    assert main(["robots", str(file), "--assume-limits"]) == 0
    out = capsys.readouterr().out
    assert "free_joint = 5" in out
    assert "the joint 5 in [-2.0000, 2.0000] rad" in out


@pytest.mark.parametrize(
    ("ik", "expected"),
    [
        ("{free_joint: 9}", "ik.free_joint: expected a joint 1 … 7, got 9"),
        ("{family: opw}", "does not have the opw structure"),
        ("{family: delta}", "ik.family"),
    ],
)
def test_a_bad_ik_block_is_one_line(tmp_path, capsys, ik, expected):
    file = _robot_file(tmp_path, ik)
    assert main(["robots", str(file), "--assume-limits"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and expected in err[0], err


def test_the_arm_angle_range_is_a_whole_turn():
    from trackplan.robots.families.base import RedundancyParameter

    arm_angle = RedundancyParameter("arm angle", -math.pi, math.pi)
    assert RedundancySpec().full_turn(arm_angle)
    assert not RedundancySpec(range=(-1.0, 1.0)).full_turn(arm_angle)
