"""``plan``, ``optimize`` and ``check`` of a case with several seams (``paths:``).

The commands in :mod:`trackplan.cli.plan` and :mod:`trackplan.cli.search` hand a case with
a ``cycle`` to these functions: same options, same exit codes, the cycle's files
(``docs/seams.md``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from rich.console import Console
from rich.markup import escape

from trackplan.case import Case
from trackplan.cli import ExitCode
from trackplan.cli.common import check_sample_times, console
from trackplan.cli.signals import stop_on_signals
from trackplan.errors import CaseError
from trackplan.planning.cycle import CycleResult


def refuse_options(**given: object) -> None:
    """Options of a single path that a cycle does not take: one clear line.

    Raises
    ------
    CaseError
        Naming the first option given.
    """
    for name, value in given.items():
        if value not in (None, False):
            option = "--" + name.replace("_", "-")
            raise CaseError(
                f"{option} applies to a single path; a case with several seams (paths:) "
                "does not take it",
                key=option,
            )


def plan_cycle_command(
    case: Case, X: np.ndarray, out: Path, *, timing: str | None, report: bool
) -> ExitCode:
    """Plan the cycle at X, write it, print it; the exit code."""
    from trackplan.outputs import write_cycle_run
    from trackplan.planning.cycle import plan_cycle

    result = plan_cycle(case, X, timing=timing)
    write_cycle_run(out, result, case, report=report)
    print_cycle(console(), result, out)
    return ExitCode.OK if result.feasible else ExitCode.INFEASIBLE


def optimize_cycle_command(case: Case, out: Path, *, report: bool, **options: object) -> ExitCode:
    """Search one placement for every seam (SIGINT and SIGTERM stop it), write the cycle,
    print it; the exit code."""
    from trackplan.outputs import write_cycle_run
    from trackplan.search.cycle_search import optimize_cycle

    with stop_on_signals() as signals:
        signals.deferring = True
        result = optimize_cycle(
            case,
            progress=lambda _: signals.raise_if_stopped(),
            **options,  # type: ignore[arg-type]
        )
        signals.deferring = False
        interrupted = result.stop_reason == "interrupted" or signals.first is not None
        marks = (
            {"status": "interrupted", "plan_status": result.final.status.value}
            if interrupted
            else None
        )
        write_cycle_run(out, result.final, case, report=report, search=result, extra=marks)
    text = console()
    text.print(
        f"{escape(result.message)} ({result.evaluations} evaluations, "
        f"{result.wall_time_s:.2f} s, seed {result.seed})"
    )
    from trackplan.search.space import bounds_note

    note = bounds_note(result.on_bounds)
    if note:
        text.print(f"  note: {escape(note)}")
    print_cycle(text, result.final, out)
    if interrupted:
        return ExitCode(signals.exit_code)
    return ExitCode.OK if result.success else ExitCode.INFEASIBLE


def check_cycle_command(case: Case, X: np.ndarray, csv: Path) -> ExitCode:
    """Re-check a cycle's trajectory.csv (its ``segment`` column says which seam is where)."""
    from trackplan.cli.summaries import print_check
    from trackplan.io.cycle_results import read_segments
    from trackplan.io.results import read_trajectory_csv
    from trackplan.planning.cycle import check_cycle_trajectory

    t, q = read_trajectory_csv(csv, case.robot.n_dof)
    segment = read_segments(csv)
    sample_time = case.task.sample_time
    check_sample_times(t, sample_time, str(csv))
    report = check_cycle_trajectory(case, X, q, sample_time, segment)
    print_check(console(), str(csv), len(t), sample_time, report)
    return ExitCode.OK if report.success else ExitCode.INFEASIBLE


def print_cycle(text: Console, result: CycleResult, out: Path) -> None:
    """A few lines on a cycle: verdict, times, the sequence, each seam, the files."""
    name = escape(result.case_name)
    if result.feasible:
        text.print(f"{name}: {escape(result.message)}")
    else:
        text.print(f"{name}: INFEASIBLE ({result.status.value}): {escape(result.message)}")
    if result.trajectory.n_samples:
        order = ", ".join(
            f"{escape(seam.name)} {'reversed' if seam.reversed else 'forward'}"
            for seam in result.seams
        )
        text.print(
            f"  cycle time = {result.duration:.3f} s (welding {result.seam_time:.3f} s, "
            f"approach, retract and air {result.air_time:.3f} s)  J = {result.objective:.4f}"
        )
        text.print(f"  sequence: {order}")
        text.print(f"  placement X = ({', '.join(f'{v:.4f}' for v in result.placement)})")
        for seam, own in zip(result.seams, result.seam_checks, strict=True):
            text.print(
                f"  {escape(seam.name)}: {seam.plan.duration:.3f} s, "
                f"max tracking error {1e3 * own.max_tracking_error:.4f} mm, "
                f"{len(seam.plan.slowdowns)} slow-downs"
            )
        cell = result.check.cell
        if cell is not None:
            text.print(
                f"  min clearance = {1e3 * cell.min_clearance:.1f} mm "
                f"({escape(cell.closest[0])} – {escape(cell.closest[1])} at "
                f"t = {cell.t_closest:.3f} s; required {1e3 * cell.clearance:.1f} mm)"
            )
    for violation in result.check.violations[:10]:
        text.print(f"  {escape(violation.message)}")
    text.print(f"  results in {escape(str(out))}/")
