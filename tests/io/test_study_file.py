"""Study files: the product of cases × robots × sweeps × seeds, and one line per bad input."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.conftest import CASES
from trackplan.errors import CaseError
from trackplan.io.case_file import load_case
from trackplan.io.robot_file import robot_to_yaml
from trackplan.io.study_file import check_set_key, load_study
from trackplan.robots.builtin import puma560


def study(tmp_path: Path, text: str) -> Path:
    file = tmp_path / "study.yaml"
    file.write_text(text, encoding="utf-8")
    return file


def test_the_jobs_are_the_product_in_order_with_overrides_applied(tmp_path: Path) -> None:
    (tmp_path / "parts").mkdir()
    for name in ("paper-line", "paper-corner"):
        (tmp_path / "parts" / f"{name}.yaml").write_text((CASES / f"{name}.yaml").read_text())
    file = study(
        tmp_path,
        "name: speeds\n"
        "cases: [parts/paper-l*.yaml, parts/*.yaml]\n"  # paper-line matched twice: once
        "robots: [ur5, puma560]\n"
        "seeds: [4, 7]\n"
        "set:\n"
        "  task.rated_speed: [0.05, 0.1]\n"
        "  optimizer.budget: [50]\n",
    )
    loaded = load_study(file)
    assert loaded.name == "speeds" and loaded.source == str(file)
    assert loaded.cases == ("paper-line", "paper-corner")
    assert loaded.robots == ("ur5", "puma560")
    assert len(loaded.jobs) == 2 * 2 * 2 * 2
    first, last = loaded.jobs[0], loaded.jobs[-1]
    assert first.key == "paper-line__ur5__task.rated_speed=0.05__s4"
    assert last.key == "paper-corner__puma560__task.rated_speed=0.1__s7"
    assert [job.seed for job in loaded.jobs[:4]] == [4, 7, 4, 7]
    assert len({job.key for job in loaded.jobs}) == len(loaded.jobs)
    for job in loaded.jobs:
        original = load_case(job.case_file)
        assert job.case.robot.name == job.robot
        assert job.case.task.rated_speed == dict(job.sweep)["task.rated_speed"]
        assert job.case.optimizer.budget == 50  # a single value is a setting, not in the label
        assert job.case.task.tolerance == original.task.tolerance
        assert job.case.source == str(tmp_path / "parts" / f"{job.case_label}.yaml")


def test_defaults_one_job_per_case_with_its_own_robot_and_seed(tmp_path: Path) -> None:
    loaded = load_study(study(tmp_path, f"cases: ['{CASES}/ur5-bead.yaml']\n"))
    (job,) = loaded.jobs
    assert job.key == "ur5-bead__ur5__base__s1"  # the case's optimizer.seed is 1
    assert (job.sweep, job.sweep_label, job.seed) == ((), "base", 1)
    assert loaded.name == "study"


def test_a_robot_file_is_relative_to_the_study(tmp_path: Path) -> None:
    (tmp_path / "arms").mkdir()
    text = robot_to_yaml(puma560()).replace("name: puma560", "name: my-puma")
    (tmp_path / "arms" / "mine.yaml").write_text(text)
    loaded = load_study(
        study(tmp_path, f"cases: ['{CASES}/paper-line.yaml']\nrobots: [arms/mine.yaml]\n")
    )
    assert loaded.robots == ("my-puma",)
    assert loaded.jobs[0].key == "paper-line__my-puma__base__s0"


@pytest.mark.parametrize(
    ("text", "key", "words"),
    [
        (
            f"cases: ['{CASES}/paper-line.yaml', 'parts/*.yaml']\n",
            "cases[1]",
            "'parts/*.yaml' matches no file",
        ),
        (
            f"cases: ['{CASES}/paper-line.yaml']\nrobots: [puma560, kuka-kr16]\n",
            "robots[1]",
            "unknown robot 'kuka-kr16': use one of",
        ),
        (
            f"cases: ['{CASES}/paper-line.yaml']\nset:\n  task.speed: [0.1]\n",
            "set.task.speed",
            "not a case key: task has no key 'speed'; did you mean 'rated_speed'?",
        ),
        (
            f"cases: ['{CASES}/paper-line.yaml']\nset:\n  task.rated_speed.max: [0.1]\n",
            "set.task.rated_speed.max",
            "not a case key: task.rated_speed holds a value",
        ),
        (
            f"cases: ['{CASES}/paper-line.yaml']\nset:\n  path.segments.line: [1]\n",
            "set.path.segments.line",
            "not a case key: path.segments holds a value",
        ),
        (
            f"cases: ['{CASES}/paper-line.yaml']\nset:\n  robot: [ur5]\n",
            "set.robot",
            "set the robot with the study's robots list",
        ),
        (
            f"cases: ['{CASES}/paper-line.yaml']\nset:\n  task.rated_speed: [0.1, -1]\n",
            "set.task.rated_speed[1]",
            "expected a number > 0, got -1 (the value -1 set in",
        ),
        (
            f"cases: ['{CASES}/paper-line.yaml']\nseeds: [0, 1, 0]\n",
            "seeds[2]",
            "0 is given twice",
        ),
        (
            f"cases: ['{CASES}/paper-line.yaml']\nrobots: [puma560, PUMA560]\n",
            "robots[1]",
            "robot 'puma560' comes twice",
        ),
        ("cases: []\n", "cases", "expected at least 1 entry"),
        (f"cases: ['{CASES}/paper-line.yaml']\nseed: [1]\n", "seed", "unknown key"),
    ],
)
def test_bad_input_is_one_line_at_the_study_key(
    tmp_path: Path, text: str, key: str, words: str
) -> None:
    file = study(tmp_path, text)
    with pytest.raises(CaseError) as caught:
        load_study(file)
    assert (caught.value.file, caught.value.key) == (str(file), key)
    assert words in caught.value.message
    assert "\n" not in caught.value.one_line()


def test_an_invalid_case_is_reported_against_the_case_file(tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        (CASES / "paper-line.yaml").read_text().replace("rated_speed: 0.15", "rated_speed: 0")
    )
    with pytest.raises(CaseError) as caught:
        load_study(study(tmp_path, "cases: [bad.yaml]\n"))
    assert (caught.value.file, caught.value.key) == (str(bad), "task.rated_speed")


def test_two_case_files_of_one_name_are_refused(tmp_path: Path) -> None:
    for folder in ("a", "b"):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "part.yaml").write_text((CASES / "paper-line.yaml").read_text())
    with pytest.raises(CaseError, match="two case files named 'part'"):
        load_study(study(tmp_path, "cases: ['*/part.yaml']\n"))


@pytest.mark.parametrize("key", ["task.rated_speed", "optimizer.budget", "placement.x", "name"])
def test_case_keys_are_accepted(key: str) -> None:
    check_set_key(key)
