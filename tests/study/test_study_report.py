"""summary.html of a study: the feasibility matrix, the best robot per part, the links."""

from __future__ import annotations

from pathlib import Path

from trackplan.status import Status
from trackplan.study import JobRow, Study
from trackplan.study.report import (
    MATRIX_ID,
    best_per_part,
    feasibility_matrix,
    write_study_report,
)


def row(case: str, robot: str, seed: int, J: float, cycle: float, ok: bool = True) -> JobRow:
    return JobRow(
        job=f"{case}__{robot}__base__s{seed}",
        case=case,
        robot=robot,
        sweep="base",
        seed=seed,
        status=Status.FEASIBLE if ok else Status.LIMITS_VIOLATED,
        success=ok,
        J=J,
        duration_s=cycle,
        cycle_time_s=cycle,
        tracking_error_m=1e-4,
        worst_margin=0.1 if ok else -0.2,
        wall_time_s=1.0,
        worker="tcp://127.0.0.1:1",
        message="feasible: every limit met" if ok else "joint 2 jerk exceeds 40",
    )


ROWS = [
    row("line", "puma560", 0, 0.40, 4.0),
    row("line", "puma560", 1, 0.35, 4.2),
    row("line", "ur5", 0, 0.35, 3.9),  # same J as the PUMA's best: the shorter cycle wins
    row("line", "ur5", 1, 0.20, 3.0, ok=False),  # least J, but infeasible
    row("bead", "puma560", 0, 2.0, 15.0, ok=False),
    row("bead", "ur5", 0, 2.1, 14.0, ok=False),
]
STUDY = Study(name="demo", jobs=(), cases=("line", "bead"), robots=("puma560", "ur5"))


def test_the_matrix_counts_feasible_jobs_per_robot_and_case() -> None:
    feasible, total = feasibility_matrix(STUDY, ROWS)
    assert feasible == [[2, 0], [1, 0]]
    assert total == [[2, 1], [2, 1]]


def test_the_best_robot_per_part_is_the_least_J_among_feasible_jobs() -> None:
    best = best_per_part(ROWS)
    assert best[("line", "base")] == ROWS[2]
    assert best[("bead", "base")] is None


def test_the_page_holds_the_matrix_the_verdicts_and_links(tmp_path: Path) -> None:
    report = tmp_path / "jobs" / ROWS[2].job / "report.html"
    report.parent.mkdir(parents=True)
    report.write_text("<html></html>")
    page = write_study_report(STUDY, ROWS, tmp_path).read_text()
    assert f'id="{MATRIX_ID}"' in page and page.count("<script") >= 3
    assert "none feasible" in page
    assert f'<a href="jobs/{ROWS[2].job}/report.html">ur5</a>' in page
    assert f'<a href="jobs/{ROWS[0].job}/report.html">' not in page  # no report written there
    assert "joint 2 jerk exceeds 40" in page
