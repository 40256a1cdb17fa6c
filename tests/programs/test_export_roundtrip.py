"""From a run folder to a controller's program and back: every format, both forms.

Each shipped case below is planned and written as a run folder, exported with
``trackplan.export`` (the path the CLI takes: replay, build, write), and the files are read
back by the language's own test parser (which imports nothing of the writer). Then:

- every target equals the plan (:func:`~tests.programs.roundtrip.assert_matches_plan`:
  Cartesian targets through the program's base and tool are the controller-world FK of the
  planned joints within 0.01 mm and 0.001°; joint targets the planned joints within 1e-6 rad);
- the joint form's targets are samples of ``trajectory.csv`` in the controller's convention;
- the configuration fields read back equal the vendor's definition, recomputed from the
  planned joints by the reference of each language (written once, in the tests);
- a program split into parts reads back as the whole one.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import trackplan
from tests.conftest import CASES
from tests.programs.fanuc_parser import parse_fanuc
from tests.programs.fanuc_reference import fanuc_config
from tests.programs.krl_parser import parse_krl
from tests.programs.krl_reference import status_turn_reference
from tests.programs.parsed import ParsedProgram
from tests.programs.rapid_parser import parse_rapid
from tests.programs.rapid_reference import reference_confdata
from tests.programs.roundtrip import (
    JOINT_TOLERANCE,
    SAME_FIELDS,
    assert_matches_plan,
    assert_same_targets,
    expected_targets,
)
from tests.programs.urscript_parser import parse_urscript
from trackplan.outputs import write_run
from trackplan.programs import Program
from trackplan.robots.model import Robot
from trackplan.writers import ExportSource

PARSERS: dict[str, Callable[[dict[str, str]], ParsedProgram]] = {
    "krl": parse_krl,
    "rapid": parse_rapid,
    "fanuc": parse_fanuc,
    "urscript": parse_urscript,
}

RUNS = [
    # (format, case): each vendor's built-in robots, and the PUMA560 (generic) where the
    # language drives it; lines, arcs, sampled curves, sharp corners, several seams with
    # approach and air moves and a reversal, couplings and moved world frames
    ("krl", "kuka-weld"),
    ("krl", "kuka-torch"),  # a torch TCP from the case file
    ("krl", "bracket-4-fillets"),
    ("rapid", "abb-weld"),
    ("rapid", "bracket-weld"),
    ("fanuc", "fanuc-weld"),
    ("fanuc", "paper-corner"),
    ("urscript", "ur5e-glue"),
]


def _fast_first(runs: list[tuple[str, str]]) -> list[object]:
    """``runs`` with the first run of each format in the fast tier, the others marked slow
    (the fast tier keeps every format; the slow tier every run)."""
    seen: set[str] = set()
    params: list[object] = []
    for format, case_name in runs:
        marks = [pytest.mark.slow] if format in seen else []
        seen.add(format)
        params.append(pytest.param(format, case_name, marks=marks))
    return params


JOINT_PERIOD_SAMPLES = 25
"""The joint form is exported every 25th sample (the parsers read thousands of lines a
second; every sample is exported in the slow tier)."""


@functools.cache
def _run_folder(case_name: str, root: Path) -> Path:
    """The shipped case planned at its example placement, written as a run folder."""
    case = trackplan.load_case(CASES / f"{case_name}.yaml")
    assert case.bounds.example is not None, f"{case_name} has no placement.example"
    result = trackplan.plan(case, np.asarray(case.bounds.example, dtype=float))
    assert result.feasible, result.message
    folder = root / case_name
    write_run(folder, result, case, report=False)
    return folder


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], Path]:
    root = tmp_path_factory.mktemp("runs")
    return lambda case_name: _run_folder(case_name, root)


def _export(
    run: Path, format: str, output: Path, **options: object
) -> tuple[dict[str, str], Program, Robot]:
    """Export ``run`` into ``output``; the files read back as text, the program in no
    language the writer printed, and the robot."""
    source = ExportSource.of(run)
    trackplan.export(source, output, format=format, **options)
    files = {file.name: file.read_bytes().decode("ascii") for file in sorted(output.iterdir())}
    program = source.program_of(options)
    return files, program, source.robot


def _assert_configurations(
    format: str, parsed: ParsedProgram, program: Program, robot: Robot
) -> None:
    """The configuration fields read back equal the vendor's definition of the planned
    joints at each Cartesian target."""
    checked = 0
    for got, want in zip(parsed.targets, expected_targets(program), strict=True):
        if want.pose is None:
            continue
        if format == "krl":
            s, t = status_turn_reference(robot, want.joints)
            assert got.config == {"S": s, "T": t}
        elif format == "rapid":
            cf1, cf4, cf6, cfx = reference_confdata(robot, want.model_joints)
            assert got.config == {"cf1": cf1, "cf4": cf4, "cf6": cf6, "cfx": cfx}
        elif format == "fanuc":
            assert got.config == fanuc_config(robot, want.model_joints, want.joints)
        else:
            assert not got.config  # URScript poses carry no configuration
        checked += 1
    assert checked > 0


@pytest.mark.parametrize(("format", "case_name"), RUNS)
def test_a_cartesian_program_reads_back_as_the_plan(
    format: str, case_name: str, runs: Callable[[str], Path], tmp_path: Path
) -> None:
    files, program, robot = _export(runs(case_name), format, tmp_path / format)
    parsed = PARSERS[format](files)
    assert_matches_plan(parsed, program, robot)
    _assert_configurations(format, parsed, program, robot)
    assert program.budget is not None and program.budget.slack >= 0.0
    kinds = {target.kind for target in parsed.targets}
    assert "joint" in kinds and kinds & {"linear", "spline"}, kinds


@pytest.mark.parametrize(("format", "case_name"), _fast_first(RUNS))
def test_a_joint_program_is_the_trajectory_sampled(
    format: str, case_name: str, runs: Callable[[str], Path], tmp_path: Path
) -> None:
    run = runs(case_name)
    source = ExportSource.of(run)
    sample_time = float(source.run.case.task.sample_time)
    if format == "urscript":  # servoj's period is a multiple of the controller's cycle too
        cycle = source.robot.convention.cycle or 0.002
        period = float(np.lcm(round(sample_time * 1e6), round(cycle * 1e6))) * 1e-6
        period *= max(1, round(JOINT_PERIOD_SAMPLES * sample_time / period))
    else:
        period = JOINT_PERIOD_SAMPLES * sample_time
    files, program, robot = _export(run, format, tmp_path / format, motion="joint", period=period)
    parsed = PARSERS[format](files)
    assert_matches_plan(parsed, program, robot)
    # the targets are samples of trajectory.csv, the last one included, in the controller's
    # convention (a first joint move to the start is the first sample)
    step = round(period / sample_time)
    table = source.table
    rows = np.unique(np.r_[np.arange(0, len(table.t), step), len(table.t) - 1])
    expected = robot.convention.to_controller(table.q[rows])
    got = np.array([target.joints for target in parsed.targets if target.kind == "joint"])
    assert got.shape[1] == robot.n_dof
    assert np.max(np.abs(got[-len(expected) :] - expected)) <= JOINT_TOLERANCE
    assert np.max(np.abs(got[0] - expected[0])) <= JOINT_TOLERANCE


@pytest.mark.parametrize(("format", "case_name"), _fast_first(RUNS))
def test_a_split_program_reads_back_as_the_whole(
    format: str, case_name: str, runs: Callable[[str], Path], tmp_path: Path
) -> None:
    run = runs(case_name)
    whole_files, program, robot = _export(run, format, tmp_path / "whole")
    parts_files, _, _ = _export(run, format, tmp_path / "parts", max_points=7)
    assert len(parts_files) > len(whole_files) or format in ("rapid", "urscript")
    whole, parts = PARSERS[format](whole_files), PARSERS[format](parts_files)
    assert len({target.part for target in parts.targets}) > 1  # really split
    assert_matches_plan(parts, program, robot)
    # KRL ends each part's SPLINE block with ENDSPLINE C_SPL at the spline's zone: a point
    # the whole passes through (zone 0 inside its block) blends in the parts
    fields = tuple(f for f in SAME_FIELDS if not (format == "krl" and f == "zone"))
    assert_same_targets(parts, whole, fields=fields)


@pytest.mark.slow
@pytest.mark.parametrize("format", list(PARSERS))
def test_every_sample_of_a_run_is_exported(
    format: str, runs: Callable[[str], Path], tmp_path: Path
) -> None:
    case_name = dict((f, c) for f, c in reversed(RUNS))[format]
    files, program, robot = _export(runs(case_name), format, tmp_path / format, motion="joint")
    parsed = PARSERS[format](files)
    assert_matches_plan(parsed, program, robot)
    assert sum(target.kind == "joint" for target in parsed.targets) >= len(
        ExportSource.of(runs(case_name)).table.t
    )
