"""Hostile and huge inputs: every one validates and plans, or is one clear line with exit 2."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

from tests.io.test_case_file import CASES, validate_fails, write_case
from trackplan.io import yaml_input
from trackplan.io.case_file import load_case
from trackplan.io.robot_file import robot_to_yaml
from trackplan.io.sizes import MAX_SAMPLE_TIME, max_samples
from trackplan.io.yaml_input import MAX_ALIAS_EXPANSION, MAX_DEPTH, MAX_YAML_VALUES, show
from trackplan.planning.objectives import joint_travel
from trackplan.robots.builtin import puma560

BILLION_LAUGHS = "name: x\na: &a [lol, lol, lol, lol, lol, lol, lol, lol, lol]\n" + "".join(
    f"{new}: &{new} [{', '.join(['*' + old] * 9)}]\n"
    for old, new in zip("abcdefgh", "bcdefghi", strict=True)
)


def _file(folder: Path, text: str) -> Path:
    file = folder / "case.yaml"
    file.write_text(text, encoding="utf-8")
    return file


def test_billion_laughs_is_refused_fast(capsys: pytest.CaptureFixture[str], tmp_path: Path):
    start = time.perf_counter()
    line = validate_fails(capsys, str(_file(tmp_path, BILLION_LAUGHS)))
    assert time.perf_counter() - start < 2.0
    assert f"expands the document beyond {MAX_ALIAS_EXPANSION} values" in line
    assert "at line" in line and len(line) < 300


def test_messages_never_render_an_unbounded_value() -> None:
    nested: list = ["lol"] * 9
    for _ in range(12):  # 9**13 entries if expanded
        nested = [nested] * 9
    start = time.perf_counter()
    assert len(show(nested)) <= 60 and len(show({"k" * 10**6: "v" * 10**6})) <= 60
    assert time.perf_counter() - start < 0.1


def test_recursive_alias_is_refused_naming_it(capsys: pytest.CaptureFixture[str], tmp_path: Path):
    line = validate_fails(capsys, str(_file(tmp_path, "name: &loop [1, *loop]\n")))
    assert "alias *loop refers to a node that contains it (recursive alias)" in line


def test_complex_key_is_refused(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    line = validate_fails(capsys, str(_file(tmp_path, "? [a, b]\n: 1\nname: x\n")))
    assert "a list or mapping as a key is not supported" in line and "line 1" in line


def test_deep_nesting_is_refused(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    line = validate_fails(capsys, str(_file(tmp_path, "name: " + "[" * 10000 + "]" * 10000)))
    assert f"nesting deeper than {MAX_DEPTH} levels" in line


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("sample_time: 1:30", "task.sample_time: expected a number, got '1:30'"),
        ("sample_time: yes", "task.sample_time: expected a number, got 'yes'"),
        ("sample_time: 1", f"task.sample_time: expected a number ≤ {MAX_SAMPLE_TIME:g}, got 1"),
    ],
)
def test_yaml_12_scalars_and_the_sample_time_bound(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, text: str, expected: str
) -> None:
    file = write_case(tmp_path)
    file.write_text(file.read_text().replace("rated_speed: 0.15", f"rated_speed: 0.15\n  {text}"))
    assert validate_fails(capsys, str(file)).endswith(expected)


def test_yaml_12_integers_and_booleans(tmp_path: Path) -> None:
    file = write_case(tmp_path, {"optimizer.seed": 1})
    file.write_text(file.read_text().replace("seed: 1", "seed: 010"))
    assert load_case(file).optimizer.seed == 10  # decimal, not YAML 1.1 octal


@pytest.mark.parametrize(
    ("changes", "expected"),
    [
        (
            {"path.segments": [{"line": {"to": [1e200, 0, 0]}}]},
            "path.segments[0].line.to[0]: expected a number ≤ 1000, got 1e+200",
        ),
        (
            {"path.segments": [{"line": {"to": [999, 0, 0]}}]},
            "path.segments[0]: the path is 999 m long, more than 262.144 m",
        ),
        (
            {
                "path.segments": [
                    {"arc": {"center": [0.1, 0, 0], "normal": [0, 0, 1], "angle": 1e12}}
                ]
            },
            "path.segments[0].arc.angle: expected at most 8192 turns",
        ),
        ({"optimizer.population": 10**12}, "optimizer.population: expected at most 504 candidates"),
        (
            {"task.rated_speed": 1e-6},
            f"task.sample_time: the trajectory would have at least 1.039e+09 samples (path "
            f"length 1.039 m / (rated speed × sample time)), more than the {max_samples(6)}",
        ),
        (
            {"path.segments": [{"points": [[0.1, 0, 0], [0.2, 0, 0], [0.1, 0, 0], [0.1, 0.1, 0]]}]},
            "path.segments[0].points[1]: the curve doubles back at point (0.2, 0, 0) m",
        ),
    ],
)
def test_sizes_overflow_and_doubling_back_are_refused_with_the_limit(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, changes: dict, expected: str
) -> None:
    line = validate_fails(capsys, str(write_case(tmp_path, changes)))
    assert line.startswith(f"{tmp_path / 'case.yaml'}: {expected}"), line
    assert "GiB" in line or "number" in line or "doubles back" in line


def test_default_weights_for_twenty_joints(tmp_path: Path) -> None:
    text = robot_to_yaml(puma560()).replace("name: puma560", "name: arm20")
    joints = [line for line in text.splitlines() if line.startswith("  - {")]
    head = text[: text.index(joints[0])]
    (tmp_path / "arm20.yaml").write_text(head + "\n".join(joints[:4] * 5) + "\n")
    case = load_case(write_case(tmp_path, {"robot": "arm20.yaml"}))
    assert case.robot.n_dof == 20
    np.testing.assert_array_equal(case.objective.weights, np.ones(20))
    q = np.random.default_rng(0).normal(size=(5, 20))
    assert joint_travel(q, case.objective.weights) == pytest.approx(
        np.abs(np.diff(q, axis=0)).sum()
    )


def test_the_shipped_cases_still_load() -> None:
    for file in sorted(CASES.glob("*.yaml")):
        assert load_case(file).name


def test_a_long_inline_list_is_refused_early_pointing_to_points_files(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    rows = "".join(f"        - [{i * 1e-4:.4f}, 0.0, 0.0]\n" for i in range(1, 100_001))
    text = (
        "name: long\nrobot: puma560\npath:\n  start: [0, 0, 0]\n  segments:\n"
        f"    - points:\n{rows}task: {{rated_speed: 0.1}}\n"
    )
    start = time.perf_counter()
    line = validate_fails(capsys, str(_file(tmp_path, text)))
    assert time.perf_counter() - start < 10.0  # the values past the limit are not parsed
    assert f"holds more than {MAX_YAML_VALUES} values" in line
    assert "points: {file: seam.csv}" in line
    assert "syntax error" not in line  # a size limit, not broken YAML
    assert ": YAML limit reached at line " in line

    # the limit counts values: 4 a point ([x, y, z]), about 20 for the rest of the file
    monkeypatch.setattr(yaml_input, "MAX_YAML_VALUES", 1000)
    for n_points, fits in ((240, True), (260, False)):
        some = "".join(f"        - [{i * 1e-4:.4f}, 0.0, 0.0]\n" for i in range(1, n_points + 1))
        file = _file(tmp_path, text.replace(rows, some))
        if fits:
            assert len(load_case(file).segments[0].points) == n_points
        else:
            assert "holds more than 1000 values" in validate_fails(capsys, str(file))


def test_an_infeasible_size_is_refused_before_any_costly_path_work(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # a seam-frame tool on a path beyond the length limit: the 2500 m of arc were built and
    # their tool frames sampled (10 s, 1 GB) before the one-line refusal
    text = (CASES / "seam-weld-fixed.yaml").read_text()
    text = text.replace("angle: 1.5707963267948966", "angle: 50000")
    file = _file(tmp_path, text)

    def costly(*args: object, **kwargs: object) -> None:
        raise AssertionError("the path was built before its size was checked")

    monkeypatch.setattr("trackplan.io.case_file.NominalPath.from_specs", costly)
    line = validate_fails(capsys, str(file))
    assert line.startswith(f"{file}: path.segments[1]: the path is 2500.38 m long, more than")


@pytest.mark.parametrize(
    ("key", "shown"),
    [("1", "1"), ("null", "null"), ("~", "null"), ("true", "true"), ("2.5", "2.5"), ("''", "''")],
)
@pytest.mark.parametrize("nested", [False, True])
def test_a_key_that_is_not_a_name_is_one_line_at_its_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, key: str, shown: str, nested: bool
) -> None:
    # pydantic's own words came out: "[1]: Keys should be strings, got true"
    text = write_case(tmp_path).read_text()
    lines = text.splitlines()
    at = lines.index("task:") + 2 if nested else len(lines) + 1
    lines.insert(at - 1, f"  {key}: 1" if nested else f"{key}: 1")
    line = validate_fails(capsys, str(_file(tmp_path, "\n".join(lines) + "\n")))
    column = 3 if nested else 1
    assert line.endswith(
        f"at line {at}, column {column}: a key must be a non-empty name, got {shown}"
    ), line
    assert "should be" not in line


def test_an_oversized_trajectory_is_refused_before_it_is_read(tmp_path: Path) -> None:
    """``check`` read a trajectory.csv of any size into memory."""
    from trackplan.errors import CaseError
    from trackplan.io.results import read_trajectory_csv
    from trackplan.io.sizes import MAX_TRAJECTORY_BYTES

    file = tmp_path / "trajectory.csv"
    with file.open("w") as handle:  # sparse: no disk is used for the gap
        handle.write("t,q1\n0,0\n")
        handle.truncate(MAX_TRAJECTORY_BYTES + 1)
    start = time.perf_counter()
    with pytest.raises(CaseError, match=r"more than the 512 MiB of the longest trajectory"):
        read_trajectory_csv(file)
    assert time.perf_counter() - start < 1.0


def test_more_samples_than_a_plan_may_have_are_refused(tmp_path: Path) -> None:
    from trackplan.errors import CaseError
    from trackplan.io.results import read_trajectory_csv

    rows = max_samples(6) + 1
    table = np.zeros((rows, 7))
    table[:, 0] = np.arange(rows) * 1e-3
    file = tmp_path / "trajectory.csv"
    np.savetxt(file, table, delimiter=",", header="t,q1,q2,q3,q4,q5,q6", comments="", fmt="%g")
    with pytest.raises(CaseError, match=rf"{rows} samples, more than the {rows - 1} a plan"):
        read_trajectory_csv(file)
