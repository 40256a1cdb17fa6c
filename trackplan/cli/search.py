"""Commands that search the placement: ``optimize`` and ``demo``."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from trackplan.cli import ExitCode
from trackplan.cli.common import (
    AssumeLimitsOption,
    TimingOption,
    app,
    console,
    method_option,
    output_folder,
    placement_option,
    shipped_cases_dir,
    timing_option,
)
from trackplan.cli.signals import SignalLog, stop_on_signals
from trackplan.errors import CaseError
from trackplan.status import Status

if TYPE_CHECKING:
    from contextlib import AbstractContextManager

    from trackplan.case import Case
    from trackplan.report.plot_worker import PlotWorker


@app.command()
def optimize(
    case: Annotated[Path, typer.Argument(help="Case file.", show_default=False)],
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = Path("runs/optimize"),
    method: Annotated[
        str | None,
        typer.Option(
            "--method",
            help="multistart, ga (the paper's), cmaes, de or random (default: optimizer.method).",
        ),
    ] = None,
    seed: Annotated[
        int | None,
        typer.Option("--seed", min=0, help="Random seed ≥ 0 (default: optimizer.seed)."),
    ] = None,
    budget: Annotated[
        int | None,
        typer.Option("--budget", min=1, help="Largest number of placement evaluations."),
    ] = None,
    restarts: Annotated[
        int | None,
        typer.Option(
            "--restarts",
            min=1,
            help="Independent runs, the best kept (default: optimizer.restarts; 1 = the "
            "paper's single GA run).",
        ),
    ] = None,
    timing: TimingOption = None,
    report: Annotated[bool, typer.Option(help="Write plots and report.html.")] = True,
    objective: Annotated[
        str | None,
        typer.Option(
            "--objective",
            help="What to minimise: travel, time, energy or copper (default: objective.kind).",
        ),
    ] = None,
    pareto: Annotated[
        str | None,
        typer.Option(
            "--pareto",
            help="Two objectives A,B (travel, time, energy, copper): an NSGA-II front instead "
            "of one placement; writes pareto.csv, pareto.png, pareto.html and front/NN/.",
        ),
    ] = None,
    assume_limits: AssumeLimitsOption = False,
) -> ExitCode:
    """Search where to place the workpiece; write the best plan, history.csv and the report.

    Writes what ``plan`` writes (trajectory.csv, result.json with the ``optimizer`` and
    ``initial`` blocks, plots and report.html unless --no-report) plus history.csv.
    Ctrl-C (SIGINT) or SIGTERM stops the search and still writes everything for the best
    placement found, with ``status: interrupted`` in result.json, and exits 130 or 143.
    """
    from contextlib import nullcontext

    workers: AbstractContextManager[PlotWorker | None] = nullcontext()
    if report and pareto is None:
        # forked first: it gets matplotlib ready on the second core while this process
        # loads the case and starts numba's kernels (closed unless the search uses it)
        from trackplan.report.plot_worker import plot_worker

        workers = plot_worker()
    with workers as worker:
        return _optimize(
            case,
            out,
            method=method,
            seed=seed,
            budget=budget,
            restarts=restarts,
            timing=timing,
            report=report,
            objective=objective,
            pareto=pareto,
            assume_limits=assume_limits,
            worker=worker,
        )


def _optimize(
    case: Path,
    out: Path,
    *,
    method: str | None,
    seed: int | None,
    budget: int | None,
    restarts: int | None,
    timing: str | None,
    report: bool,
    objective: str | None,
    pareto: str | None,
    assume_limits: bool,
    worker: PlotWorker | None,
) -> ExitCode:
    """``optimize`` once its plot worker is started."""
    from trackplan.io.case_file import load_case

    out = output_folder(out)
    method = method_option(method)
    timing = timing_option(timing)
    loaded = load_case(case, assume_limits=assume_limits)
    if worker is not None:
        worker.prepare(loaded.machine.n_dof)
    if objective is not None:
        from trackplan.planning.objectives import with_objective

        loaded = with_objective(loaded, objective)
    if pareto is not None and len(loaded.seams) > 1:
        raise CaseError(
            "--pareto applies to a single path; a case with several seams (paths:) "
            "does not take it",
            key="--pareto",
        )
    if pareto is not None:
        return _pareto(loaded, pareto, out, seed=seed, timing=timing, report=report)
    return _search_and_write(
        loaded,
        out,
        report=report,
        worker=worker,
        method=method,
        seed=seed,
        budget=budget,
        restarts=restarts,
        timing=timing,
    )


@app.command()
def demo(
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = Path("runs/demo"),
) -> ExitCode:
    """Optimize the paper's corner case (cases/paper-corner.yaml) end to end, with the report."""
    from trackplan.io.case_file import load_case
    from trackplan.report.plot_worker import plot_worker

    out = output_folder(out)
    file = shipped_cases_dir() / "paper-corner.yaml"
    if not file.is_file():
        raise CaseError("the shipped demo case is missing (run from a source checkout)", str(file))
    with plot_worker() as worker:  # forked first, as in optimize
        loaded = load_case(file)
        if worker is not None:
            worker.prepare(loaded.machine.n_dof)
        code = _search_and_write(loaded, out, report=True, worker=worker)
    typer.echo(f"report: {(out / 'report.html').resolve()}")
    return code


@app.command("map")
def map_command(
    case: Annotated[Path, typer.Argument(help="Case file.", show_default=False)],
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = Path("runs/map"),
    rpy: Annotated[
        tuple[float, float, float] | None,
        typer.Option(
            "--rpy",
            help="ROLL PITCH YAW of every placement, rad (default: the search's best).",
            show_default=False,
        ),
    ] = None,
    z: Annotated[
        float | None,
        typer.Option("--z", help="Height of every placement, m (default: the search's best)."),
    ] = None,
    points: Annotated[
        int,
        typer.Option("--points", help="Grid points along x and along y (2 to 501)."),
    ] = 41,
) -> ExitCode:
    """Map feasibility (reach, joint limit, collision) and J over an x-y grid of placements.

    Writes map.png, map.csv and map.html. Without --rpy and --z the case's placement
    search runs first and the map keeps its best placement's height and orientation.
    """
    import numpy as np

    from trackplan.io.case_file import load_case
    from trackplan.io.map_file import write_map_csv
    from trackplan.report.cell_figures import write_map_report
    from trackplan.search.placement_map import check_map_points, placement_map

    check_map_points(points, "--points")
    out = output_folder(out)
    given = placement_option(
        (0.0, 0.0, z or 0.0, *(rpy or (0.0, 0.0, 0.0))), ("--z",) * 3 + ("--rpy",) * 3
    )
    loaded = load_case(case)
    reference = np.full(6, np.nan)  # x, y stay unset unless the search ran
    if rpy is None or z is None:
        with stop_on_signals() as signals:
            signals.deferring = True
            reference = np.asarray(_search(loaded, signals).X, dtype=float)
    if z is not None and given is not None:
        reference[2] = given[2]
    if rpy is not None and given is not None:
        reference[3:] = given[3:]
    pmap = placement_map(loaded, reference, n_points=points)
    write_map_csv(pmap, out)
    write_map_report(pmap, out)
    typer.echo(
        f"{loaded.name}: placement map at z = {pmap.z:.4f} m, rpy = "
        f"({', '.join(f'{v:.4f}' for v in pmap.rpy)}) rad: feasible on "
        f"{100 * pmap.feasible_share:.0f} % of {points} x {points} placements"
    )
    typer.echo(f"  results in {out}/")
    return ExitCode.OK


def _pareto(
    case: Case, pair: str, out: Path, *, seed: int | None, timing: str | None, report: bool
) -> ExitCode:
    """``optimize --pareto A,B``: the front, every point re-planned, its files and plots."""
    from rich.markup import escape

    from trackplan.io.pareto import write_pareto_csv
    from trackplan.outputs import write_run
    from trackplan.search.pareto import pareto_front, parse_objective_pair

    names = parse_objective_pair(pair, case)
    result = pareto_front(case, names, seed=seed, timing=timing)
    rows = write_pareto_csv(result, out)
    for row, plan in zip(rows, result.plans, strict=True):
        write_run(out / str(row["folder"]), plan, case, report=report)
    if report:
        from trackplan.report.pareto import write_pareto_report

        write_pareto_report(result, case.name, rows, out)
    text = console()
    text.print(f"{escape(result.message)}, {result.wall_time_s:.2f} s (seed {result.seed})")
    a, b = result.objectives
    for row in rows:
        state = "feasible" if row["feasible"] else "INFEASIBLE"
        text.print(f"  {row['point']:>2}  {a} {row[a]:.4g}  {b} {row[b]:.4g}  {state}")
    text.print(f"  results in {escape(str(out))}/")
    return ExitCode.OK if result.success else ExitCode.INFEASIBLE


def _search_and_write(  # type: ignore[no-untyped-def]
    case: Case, out: Path, *, report: bool, worker: PlotWorker | None, **options
) -> ExitCode:
    """Search (SIGINT and SIGTERM stop it), write the run (its plots by ``worker`` when
    there is one), print it; the exit code."""
    from trackplan.cli.warmup import compile_shared, late_compiles
    from trackplan.forking import forked_pool
    from trackplan.search.plan_calls import seam_geometries
    from trackplan.timing import time_law

    # built first (numba's start), so that the processes forked below share them, with the
    # kernels the search and the plans both start with (compiled once on a first run)
    timing = time_law(options.get("timing") or case.task.timing).timing
    geometries = seam_geometries(case, timing)
    compile_shared(case)
    # a second signal while writing stops the writing
    with late_compiles(), stop_on_signals() as signals:
        signals.deferring = True  # the search polls after each generation
        with forked_pool() as background:  # the plans at full Ts, beside the search
            result = _search(case, signals, geometries=geometries, background=background, **options)
        signals.deferring = False
        interrupted = result.status is Status.INTERRUPTED or signals.first is not None
        marks = _interrupted_marks(result, signals) if interrupted else None
        _write_and_print(out, result, case, report=report, worker=worker, extra=marks)
    if interrupted:
        return ExitCode(signals.exit_code)
    return ExitCode.OK if result.success else ExitCode.INFEASIBLE


def _write_and_print(  # type: ignore[no-untyped-def]
    out: Path, result, case: Case, *, report: bool, worker: PlotWorker | None, extra
) -> None:
    """Write the search's run folder and print its summary (one seam or several)."""
    from trackplan.cli.summaries import print_search
    from trackplan.outputs import write_search_run

    write_search_run(out, result, case, report=report, extra=extra, plot_worker=worker)
    print_search(console(), result, out, rated_speed=case.task.rated_speed)


def _interrupted_marks(result, signals: SignalLog) -> dict:  # type: ignore[no-untyped-def]
    """The keys of result.json that mark a search stopped by a signal."""
    name = "SIGTERM" if signals.exit_code == ExitCode.TERMINATED else "SIGINT"
    return {
        "status": Status.INTERRUPTED.value,
        "plan_status": result.final.status.value,
        "interrupted": {
            "signal": name,
            "evaluations": int(result.evaluations),
            "message": f"{name} stopped the search after {result.evaluations} evaluations; "
            "this is the best placement found until then",
        },
    }


def _search(case: Case, signals: SignalLog, **options):  # type: ignore[no-untyped-def]
    """Run the placement search, with a progress bar when stderr is a terminal; a signal
    recorded in ``signals`` stops it after the current generation."""
    from rich.console import Console

    from trackplan.search.optimize import optimize

    err = Console(stderr=True)
    if not err.is_terminal:
        return optimize(case, progress=lambda _: signals.raise_if_stopped(), **options)
    import numpy as np
    from rich.progress import Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

    columns = (SpinnerColumn(), TextColumn("{task.description}"), TimeElapsedColumn())
    # refreshed after each generation, not by a thread: a background executor forks
    with Progress(*columns, console=err, transient=True, auto_refresh=False) as bar:
        task = bar.add_task("placement search: starting", total=None)

        def show(record) -> None:  # type: ignore[no-untyped-def]
            best = (
                f"best J {record.best_objective:.4f}"
                if np.isfinite(record.best_objective)
                else f"best fitness {record.best:.4g} (none feasible yet)"
            )
            bar.update(
                task,
                description=f"generation {record.generation}  {record.evaluations} evaluations  "
                f"{best}  feasible {100 * record.feasible_share:.0f} %",
                refresh=True,
            )
            signals.raise_if_stopped()

        return optimize(case, progress=show, **options)
