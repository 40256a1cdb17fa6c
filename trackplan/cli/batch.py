"""Batch studies: ``batch`` runs a study file (cases × robots × sweeps × seeds) on Dask."""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path
from typing import Annotated

import typer

from trackplan.cli import ExitCode
from trackplan.cli.common import app, output_folder
from trackplan.cli.common import console as _console
from trackplan.errors import CaseError
from trackplan.status import Status


@app.command()
def batch(
    study: Annotated[Path, typer.Argument(help="Study file.", show_default=False)],
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = Path("runs/batch"),
    workers: Annotated[
        int | None,
        typer.Option("--workers", help="Local worker processes (default: one per core)."),
    ] = None,
    scheduler: Annotated[
        str | None,
        typer.Option("--scheduler", help="Run on an existing Dask cluster: tcp://HOST:PORT."),
    ] = None,
    resume: Annotated[
        bool, typer.Option("--resume", help="Keep the jobs already complete in --out.")
    ] = False,
    report: Annotated[bool, typer.Option(help="Write each run's plots and report.html.")] = True,
) -> ExitCode:
    """Run a study (cases × robots × sweeps × seeds) on Dask; write summary.csv and summary.html.

    Exit code 0 when every job found a feasible placement, 3 when some did not, 1 when a
    job failed, 130 on Ctrl-C (pending jobs cancelled, the summary of the finished written).
    """
    from rich.markup import escape

    from trackplan.io.study_file import load_study
    from trackplan.study import connect, run_study

    out = output_folder(out)
    if workers is not None and scheduler is not None:
        raise CaseError("give --workers or --scheduler, not both", key="--scheduler")
    loaded = load_study(study)
    client = connect(scheduler) if scheduler is not None else None
    try:
        with _study_progress(len(loaded.jobs)) as show:
            result = run_study(
                loaded, out, client, workers=workers, resume=resume, report=report, progress=show
            )
    finally:
        if client is not None:
            client.close()  # type: ignore[no-untyped-call]  # distributed is unannotated
    console = _console()
    console.print(f"{escape(loaded.name)}: {escape(result.message)} in {result.wall_time_s:.1f} s")
    for row in result.rows:
        if row.failed:
            console.print(f"  FAILED {escape(row.job)}: {escape(row.message)}")
    console.print(f"  summary in {escape(str(out / 'summary.csv'))} and summary.html")
    if result.status is Status.INTERRUPTED:
        return ExitCode.INTERRUPTED
    if result.n_failed:
        return ExitCode.INTERNAL_ERROR
    return ExitCode.OK if result.success else ExitCode.INFEASIBLE


@contextmanager
def _study_progress(total: int):  # type: ignore[no-untyped-def]
    """A progress callback for run_study: a rich bar on a terminal, else one line per job."""
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    console = Console(stderr=True)
    if not console.is_terminal:

        def line(state) -> None:  # type: ignore[no-untyped-def]
            row = state.last
            if row is not None:
                figures = f"J = {row.J:.4f}, " if row.success else ""
                typer.echo(
                    f"[{state.done}/{state.total}] {row.job}: {row.status.value} "
                    f"({figures}{row.wall_time_s:.1f} s on {row.worker})"
                )

        yield line
        return
    columns = (
        TextColumn("batch"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.fields[running]} running, {task.fields[failed]} failed"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
    )
    with Progress(*columns, console=console, transient=True) as bar:
        task = bar.add_task("batch", total=total, running=0, failed=0)

        def update(state) -> None:  # type: ignore[no-untyped-def]
            bar.update(
                task,
                total=state.total - state.skipped,
                completed=state.done - state.skipped,
                running=state.running,
                failed=state.failed,
            )

        yield update
