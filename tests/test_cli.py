"""The command line: exit codes, one-line errors, and the output of each command."""

from __future__ import annotations

import importlib
import math
import subprocess
import sys
from pathlib import Path

import pytest

import trackplan
from tests.conftest import CASES, REPO
from trackplan import cli
from trackplan.cli import ExitCode, main
from trackplan.cli.common import shipped_cases_dir
from trackplan.io import case_file
from trackplan.io.robot_file import load_robot_text
from trackplan.robots.builtin import ur5


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_validate_prints_length_and_corner_angle(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "validate", str(CASES / "paper-corner.yaml"))
    assert (code, err) == (0, "")
    assert f"length {0.5 + math.sqrt(0.29):.4f} m" in out
    corner = math.degrees(math.acos(0.2 / math.sqrt(0.29)))  # between (-1, 0, 0) and (-0.2, 0, 0.5)
    assert f"{corner:.1f}°" in out and "68.2°" in out
    assert "2 segments" in out and "puma560" in out


def test_validate_reports_each_bad_case_and_goes_on(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: bad\n", encoding="utf-8")
    code, out, err = run(capsys, "validate", str(bad), str(CASES / "paper-line.yaml"))
    assert code == ExitCode.BAD_INPUT
    assert err.strip() == f"{bad}: path: required key is missing"
    assert "paper-line" in out and "length 0.5831 m" in out


def test_robots_table_and_yaml(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "robots")
    assert code == 0
    for name in ("puma560", "ur5e", "kuka_kr6_r700_sixx", "abb_irb2400", "fanuc_m20ia"):
        assert name in out
    assert "opw" in out and "ur" in out and "1.162" in out  # family and reach columns
    code, out, _ = run(capsys, "robots", "ur5")
    assert code == 0
    assert "[-360, 360]" in out and "IK family: ur" in out and "d1 = 0.089159" in out
    code, out, _ = run(capsys, "robots", "kuka_kr6_r700_sixx")
    assert "IK family: opw" in out and "a1 = 0.025" in out and "c4 = 0.08" in out
    assert "assumption: acceleration and jerk limits are assumed" in out
    code, out, _ = run(capsys, "robots", "--yaml", "ur5")
    assert code == 0
    assert load_robot_text(out).name == ur5().name


def test_robots_yaml_of_an_unknown_robot(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "robots", "--yaml", "kuka")
    assert code == 2 and err.startswith("robot: unknown robot 'kuka'")


def test_cases_lists_the_shipped_cases(capsys: pytest.CaptureFixture[str]) -> None:
    assert shipped_cases_dir() == CASES
    code, out, err = run(capsys, "cases")
    assert (code, err) == (0, "")
    for name in ("paper-line", "paper-circle", "paper-corner", "ur5-bead"):
        assert name in out
    assert "1.0385" in out and "68.2°" in out


def test_cases_lists_each_seam_of_a_case_with_several(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code, out, err = run(capsys, "cases")
    assert (code, err) == (0, "")
    lines = out.splitlines()
    (row,) = [line for line in lines if "bracket-4-fillets.yaml" in line]
    cells = [cell.strip() for cell in row.strip("│ ").split("│")]
    # the case's own row: its 4 seams and their 5 segments, 0.5885 m in all
    assert cells[:4] == ["bracket-4-fillets", "puma560", "4", "5"]
    length = 0.1 + 0.1 + 2 * math.pi * 0.03 + 0.15 + 0.05
    assert cells[4] == f"{length:.4f}"
    below = lines[lines.index(row) + 1 : lines.index(row) + 5]
    seams = [[cell.strip() for cell in line.strip("│ ").split("│")] for line in below]
    assert [(s[0], s[3], s[4]) for s in seams] == [
        ("· rib-left", "1", "0.1000"),
        ("· rib-right", "1", "0.1000"),
        ("· boss", "1", f"{2 * math.pi * 0.03:.4f}"),
        ("· gusset", "2", "0.2000"),
    ]
    assert seams[3][5] == "90.0°"


@pytest.mark.parametrize(
    ("args", "code"),
    [
        ((), 2),
        (("--help",), 0),
        (("validate",), 2),
        (("bogus",), 2),
        (("validate", "--nope", "x"), 2),
    ],
)
def test_usage(capsys: pytest.CaptureFixture[str], args: tuple[str, ...], code: int) -> None:
    actual, out, err = run(capsys, *args)
    assert actual == code
    assert "Traceback" not in out + err
    assert "Usage" in out + err


def test_internal_error_is_one_line_without_traceback(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    def broken(file: object, **options: object) -> None:
        raise RuntimeError("boom\nsecond line")

    monkeypatch.setattr(case_file, "load_case", broken)
    monkeypatch.delenv(cli.DEBUG_ENV, raising=False)
    code, _, err = run(capsys, "validate", "any.yaml")
    assert code == ExitCode.INTERNAL_ERROR
    assert err == "internal error: RuntimeError: boom second line\n"


@pytest.mark.parametrize("how", ["option", "environment"])
def test_debug_prints_the_traceback(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, how: str
) -> None:
    def broken(file: object, **options: object) -> None:
        raise RuntimeError("boom")

    monkeypatch.setattr(case_file, "load_case", broken)
    if how == "environment":
        monkeypatch.setenv(cli.DEBUG_ENV, "1")
        args: tuple[str, ...] = ("validate", "any.yaml")
    else:
        monkeypatch.delenv(cli.DEBUG_ENV, raising=False)
        args = ("--debug", "validate", "any.yaml")
    code, _, err = run(capsys, *args)
    assert code == ExitCode.INTERNAL_ERROR
    assert "Traceback" in err and err.rstrip().endswith("internal error: RuntimeError: boom")


def test_public_api() -> None:
    assert trackplan.__version__
    for name in trackplan.__all__:
        assert getattr(trackplan, name) is not None
    case = trackplan.load_case(CASES / "paper-corner.yaml")
    assert isinstance(case, trackplan.Case) and isinstance(case.robot, trackplan.Robot)
    kinematics = importlib.import_module("trackplan.robots.kinematics")
    assert kinematics.forward_kinematics(case.robot, [0.0] * 6).shape == (4, 4)
    assert kinematics.jacobian(case.robot, [0.0] * 6).shape == (6, 6)
    with pytest.raises(AttributeError):
        trackplan.no_such_name  # noqa: B018


def test_installed_command_validates_a_shipped_case() -> None:
    command = Path(sys.executable).parent / "trackplan"
    result = subprocess.run(
        [str(command), "validate", "cases/paper-corner.yaml"],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert "68.2°" in result.stdout


def test_python_dash_m_reports_bad_input(tmp_path: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "trackplan", "validate", str(tmp_path / "missing.yaml")],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert result.returncode == 2
    assert result.stderr == f"{tmp_path / 'missing.yaml'}: case file not found\n"


def test_plan_summary_gives_the_top_speed_when_no_sample_runs_at_the_rated_speed() -> None:
    """A plan whose speed curve cruises just below the rated speed (the continuous curve of
    a free spin plans at 99.9 % of its caps) printed "rated speed on 0.0 % of the path":
    true to the 0.01 % but meaningless. When the share would read 0.0 % it prints the top
    speed and its share of the rated speed instead; a plan that runs at the rated speed
    keeps the share of the path."""
    import dataclasses
    import io

    from rich.console import Console

    from tests.report.conftest import corner_case, plan_corner
    from trackplan.cli.summaries import print_plan
    from trackplan.robots.builtin import puma560

    case = corner_case(puma560())
    result = plan_corner(case)
    below = dataclasses.replace(
        result,
        rated_speed_fraction=0.0,
        trajectory=dataclasses.replace(result.trajectory, speed=0.999 * result.trajectory.speed),
    )
    top = 0.999 * float(result.trajectory.speed.max())
    for plan, expected, absent in (
        (
            result,
            f"rated speed on {100 * result.rated_speed_fraction:.1f} % of the path",
            "top speed",
        ),
        (
            below,
            f"top speed = {top:.4f} m/s ({100 * top / case.task.rated_speed:.1f} % of the "
            "rated speed)",
            "rated speed on",
        ),
    ):
        out = io.StringIO()
        print_plan(
            Console(file=out, width=400), plan, Path("runs/x"), rated_speed=case.task.rated_speed
        )
        assert expected in out.getvalue()
        assert absent not in out.getvalue()


def test_validate_takes_assume_limits_as_its_message_says(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    from trackplan.io.robot_file import LIBRARY_DIR

    (tmp_path / "ur5e.urdf").write_text((LIBRARY_DIR / "ur5e.urdf").read_text())
    (tmp_path / "bead.csv").write_text((CASES / "bead.csv").read_text())
    case = (CASES / "ur5-bead.yaml").read_text(encoding="utf-8")
    assert "robot: ur5\n" in case
    (tmp_path / "case.yaml").write_text(case.replace("robot: ur5\n", "robot: ur5e.urdf\n"))
    code, _, err = run(capsys, "validate", str(tmp_path / "case.yaml"))
    assert code == ExitCode.BAD_INPUT and "or pass --assume-limits" in err
    code, out, err = run(capsys, "validate", str(tmp_path / "case.yaml"), "--assume-limits")
    assert (code, err) == (0, "") and "ur5e" in out


def test_the_plan_summary_has_a_cycle_block_only_where_moves_join_seams(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    corner = str(CASES / "paper-corner.yaml")
    single = run(capsys, "plan", corner, "--no-report", "--out", str(tmp_path / "one"))
    X = ("0.2149", "-0.4997", "-0.2996", "0.0463", "-0.0083", "-2.6086")  # docs/seams.md
    joined = run(
        capsys,
        *("plan", str(CASES / "bracket-4-fillets.yaml"), "--placement", *X),
        *("--no-report", "--out", str(tmp_path / "four")),
    )
    assert single[0] == joined[0] == 0
    assert "J = " in single[1] and "cycle time" not in single[1] and "sequence:" not in single[1]
    assert "cycle time = " in joined[1] and "sequence: " in joined[1]
