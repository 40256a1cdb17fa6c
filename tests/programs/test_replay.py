"""Replaying a run: its case re-planned where the run was, equal to trajectory.csv, or refused."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import CASES
from trackplan.cli import main
from trackplan.errors import CaseError
from trackplan.io.case_file import load_case
from trackplan.io.run_folder import HASH_KEY, file_sha256
from trackplan.programs.replay import JOINT_TOLERANCE, replay_plan, replay_run

PLACEMENTS = {  # placements an optimize run found (budget 20): reachable, quick to plan
    "kuka-weld": "0.4575 -0.1439 0.2199 0.0057 0.0065 1.5890",
    "bracket-4-fillets": "0.3017 -0.3497 -0.2910 0.0296 -0.0269 -2.8133",
    "seam-weld-free": "0.2871 0.2336 -0.0497 -0.0645 -0.1609 2.1429",
    "ur5e-glue": "-0.2260 -0.4929 0.1229 0.1319 0.2013 -1.3698",
}


def _plan_run(folder: Path, case: str) -> Path:
    """A run of a shipped case at its placement above (``plan --placement``)."""
    run = folder / case
    code = main(
        [
            "plan",
            str(CASES / f"{case}.yaml"),
            "--out",
            str(run),
            "--no-report",
            "--placement",
            *PLACEMENTS[case].split(),
        ]
    )
    assert code in (0, 3)  # a run is replayed whatever its verdict
    return run


@pytest.fixture(scope="module")
def kuka_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One OPW seam (KUKA KR6 R700, limits assumed)."""
    return _plan_run(tmp_path_factory.mktemp("replay"), "kuka-weld")


def _copy(run: Path, tmp_path: Path) -> Path:
    """A copy of a run folder to edit."""
    return Path(shutil.copytree(run, tmp_path / run.name))


def _edit_summary(run: Path, **changes: object) -> None:
    summary = json.loads((run / "result.json").read_text())
    for key, value in changes.items():
        if value is None:
            summary.pop(key)
        else:
            summary[key] = value
    (run / "result.json").write_text(json.dumps(summary))


def _assert_replays(run: Path, case: str) -> None:
    replayed = replay_run(run)
    summary = json.loads((run / "result.json").read_text())
    assert summary["case_file"] == str((CASES / f"{case}.yaml").resolve())
    assert replayed.folder == run and replayed.case.name == case
    written = np.loadtxt(run / "trajectory.csv", delimiter=",", skiprows=1, ndmin=2, usecols=0)
    assert replayed.plan.trajectory.n_samples == len(written) == len(replayed.table.t)
    np.testing.assert_allclose(replayed.plan.trajectory.q, replayed.table.q, rtol=0, atol=1e-9)
    np.testing.assert_allclose(replayed.plan.trajectory.t, replayed.table.t, rtol=0, atol=1e-12)
    assert replayed.plan.branch == summary["branch"]
    visits = [(v.seam, v.reversed) for v in replayed.plan.sequence.visits]
    names = replayed.case.seam_names
    assert [(names[s], r) for s, r in visits] == [
        (v["seam"], v["reversed"]) for v in summary["sequence"]
    ]


def test_a_single_seam_opw_run_replays(kuka_run: Path) -> None:
    _assert_replays(kuka_run, "kuka-weld")
    replayed = replay_run(kuka_run / "trajectory.csv")  # its CSV names the folder too
    assert replayed.folder == kuka_run
    assert "assumptions" in replayed.summary["robot"]  # loaded with the assumed limits


def test_a_free_spin_run_replays_with_its_chosen_spin(tmp_path: Path) -> None:
    run = _plan_run(tmp_path, "seam-weld-free")
    _assert_replays(run, "seam-weld-free")
    summary = json.loads((run / "result.json").read_text())
    spin = summary["spin"]["value"]
    assert spin != 0.0  # optimised for the placement, not the middle of the range
    replayed = replay_run(run)
    assert replayed.plan.joint_path.tool.spin.as_dict() == {"value": pytest.approx(spin, abs=1e-12)}


def test_a_run_of_several_seams_with_approaches_replays(tmp_path: Path) -> None:
    run = _plan_run(tmp_path, "bracket-4-fillets")
    summary = json.loads((run / "result.json").read_text())
    assert len(summary["seams"]) == 4 and summary["approach"] > 0
    assert any(visit["reversed"] for visit in summary["sequence"])  # directions matter
    _assert_replays(run, "bracket-4-fillets")


def test_a_ur_run_replays(tmp_path: Path) -> None:
    _assert_replays(_plan_run(tmp_path, "ur5e-glue"), "ur5e-glue")


def test_a_plan_in_memory_replays_as_it_is(kuka_run: Path) -> None:
    replayed = replay_run(kuka_run)
    again = replay_plan(replayed.plan, replayed.case)
    assert again.folder is None and again.plan is replayed.plan
    np.testing.assert_array_equal(again.table.q, replayed.plan.trajectory.q)
    assert again.summary["case_file"] == replayed.summary["case_file"]
    assert again.table.joint_names == replayed.case.robot.joint_names


def test_a_run_without_case_file_needs_the_case(kuka_run: Path, tmp_path: Path) -> None:
    run = _copy(kuka_run, tmp_path)
    _edit_summary(run, case_file=None)
    with pytest.raises(CaseError) as error:
        replay_run(run)
    assert error.value.key == "--case"
    assert str(error.value) == (
        "--case: the run does not say which case it was planned from: give --case CASE"
    )
    case_file = CASES / "kuka-weld.yaml"
    assert replay_run(run, case_file).case.name == "kuka-weld"  # a file
    gone = tmp_path / "moved.yaml"
    _edit_summary(run, case_file=str(gone))
    with pytest.raises(CaseError) as error:
        replay_run(run)
    assert str(error.value) == (
        f"--case: the run was planned from {str(gone)!r}, which is no longer there: "
        "give --case CASE"
    )
    loaded = load_case(case_file, assume_limits=True)
    assert replay_run(run, loaded).case is loaded  # a Case


def test_another_case_is_refused(kuka_run: Path, tmp_path: Path) -> None:
    slower = tmp_path / "kuka-weld.yaml"
    text = (CASES / "kuka-weld.yaml").read_text()
    slower.write_text(text.replace("rated_speed: 0.02 ", "rated_speed: 0.019 "))
    with pytest.raises(CaseError, match=r"^--case: the case does not reproduce the run \(\d+ "):
        replay_run(kuka_run, slower)
    with pytest.raises(CaseError, match=r"the case's seams \(paper-line\) are not the run's"):
        replay_run(kuka_run, CASES / "paper-line.yaml")


def test_an_edited_trajectory_is_refused(kuka_run: Path, tmp_path: Path) -> None:
    run = _copy(kuka_run, tmp_path)
    csv = run / "trajectory.csv"
    lines = csv.read_text().splitlines()
    cells = lines[1001].split(",")  # sample 1000: t = 4.000 s
    cells[3] = repr(float(cells[3]) + 2.1e-2)  # joint 3
    lines[1001] = ",".join(cells)
    csv.write_text("\n".join(lines) + "\n")
    with pytest.raises(CaseError, match="files of two runs are mixed"):
        replay_run(run)  # the hash result.json records no longer matches
    _edit_summary(run, **{HASH_KEY: file_sha256(csv)})  # edited with its hash
    with pytest.raises(CaseError) as error:
        replay_run(run)
    assert str(error.value) == (
        "--case: the case does not reproduce the run (joint 3 differs by 2.1e-02 rad at "
        "t = 4.000 s): give the case the run was planned from, or plan again"
    )
    # within the tolerance: the re-plan is the run
    cells[3] = repr(float(cells[3]) - 2.1e-2 + JOINT_TOLERANCE / 2)
    lines[1001] = ",".join(cells)
    csv.write_text("\n".join(lines) + "\n")
    _edit_summary(run, **{HASH_KEY: file_sha256(csv)})
    assert replay_run(run).table.q[1000, 2] == float(cells[3])


def test_a_bare_csv_or_a_summary_without_placement_is_refused(
    kuka_run: Path, tmp_path: Path
) -> None:
    bare = tmp_path / "motion.csv"
    shutil.copy(kuka_run / "trajectory.csv", bare)
    with pytest.raises(CaseError, match="a program needs a run folder"):
        replay_run(bare)
    run = _copy(kuka_run, tmp_path)
    _edit_summary(run, placement=None)
    with pytest.raises(CaseError, match=r"lacks the run's placement.*plan the case again"):
        replay_run(run)


@pytest.mark.parametrize("reverse", [False, True])
def test_a_varying_spin_of_a_reversed_seam_replays(reverse: bool, tmp_path: Path) -> None:
    from tests.planning.test_cycle import X, spun_case
    from trackplan.io.results import write_plan_files
    from trackplan.planning.plan import plan
    from trackplan.planning.sequence import Sequence, Visit

    case = spun_case({}, {"spin": "free-varying", "spin_range": [-0.5, 0.5], "spin_rate": 5.0})
    variables = np.r_[-0.3, np.linspace(1.0, -0.2, case.seams[1].task.tool.n_spin - 1)]
    order = Sequence(visits=(Visit(0, False), Visit(1, reverse)), cost=0.0, exact=False)
    cycle = plan(case, X, sequence=order, spins=(None, variables))
    assert cycle.success, cycle.message
    write_plan_files(cycle, case, tmp_path)
    summary = json.loads((tmp_path / "result.json").read_text())
    assert summary["case_file"] is None  # built in Python: the case must be given
    with pytest.raises(CaseError, match="give --case CASE"):
        replay_run(tmp_path)
    replayed = replay_run(tmp_path, case)
    np.testing.assert_allclose(replayed.plan.trajectory.q, replayed.table.q, rtol=0, atol=1e-9)
    np.testing.assert_allclose(
        replayed.plan.trajectory.spin, cycle.trajectory.spin, rtol=0, atol=1e-12
    )


def test_the_run_records_its_robot_file(kuka_run: Path, tmp_path: Path) -> None:
    from trackplan.io.robot_file import robot_to_yaml
    from trackplan.robots.builtin import puma560

    assert json.loads((kuka_run / "result.json").read_text())["robot_file"] is None  # built-in
    (tmp_path / "robots").mkdir()
    (tmp_path / "robots" / "arm.yaml").write_text(robot_to_yaml(puma560()))
    text = (CASES / "paper-line.yaml").read_text()
    case = tmp_path / "line.yaml"
    case.write_text(text.replace("robot: puma560", "robot: robots/arm.yaml"))
    run = tmp_path / "run"
    assert main(["plan", str(case), "--out", str(run), "--no-report"]) == 0
    summary = json.loads((run / "result.json").read_text())
    assert summary["robot_file"] == str((tmp_path / "robots" / "arm.yaml").resolve())
    assert summary["case_file"] == str(case.resolve())
    assert replay_run(run).case.robot.name == "puma560"
