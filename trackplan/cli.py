"""The ``trackplan`` command line.

Commands: ``validate``, ``robots``, ``cases``, ``plan``, ``check``, ``optimize``, ``export``,
``demo`` and ``batch`` (the README has the command table).

Exit codes: 0 ok, 1 internal error, 2 bad input, 3 infeasible (:class:`ExitCode`).
:func:`main` never raises: a :class:`~trackplan.errors.CaseError` becomes one line on
stderr and exit code 2; any other exception one line ``internal error: ...`` and exit
code 1, with the traceback only under ``trackplan --debug`` or ``TRACKPLAN_DEBUG=1``.

Adding a command
----------------
A command is a thin function on :data:`app` that returns an :class:`ExitCode`:
parse (typer does it from the signature) → load (:mod:`trackplan.io`) → compute (the
pure API) → save (:mod:`trackplan.io`) → exit code. It raises ``CaseError`` for bad input
and lets :func:`main` report it; it prints results with :func:`_console` or
``typer.echo``::

    @app.command()
    def plan(
        case: Annotated[Path, typer.Argument(help="Case file.")],
        out: Annotated[Path, typer.Option(help="Output folder.")] = Path("runs/plan"),
    ) -> ExitCode:
        \"\"\"Plan the trajectory of one placement.\"\"\"
        loaded = load_case(case)
        result = plan_placement(loaded, loaded.bounds.example)
        write_run(out, result, loaded)
        return ExitCode.OK if result.success else ExitCode.INFEASIBLE
"""

from __future__ import annotations

import enum
import os
import sys
import traceback
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import numpy as np
import typer
from rich.console import Console
from rich.markup import escape
from rich.table import Table

import trackplan
from trackplan.allocator import keep_freed_memory
from trackplan.case import Case
from trackplan.choices import Timing, choose
from trackplan.errors import CaseError
from trackplan.io.case_file import load_case
from trackplan.io.robot_file import builtin_names, builtin_robot, load_robot_spec, robot_to_yaml
from trackplan.paths import NominalPath
from trackplan.robots.model import Robot
from trackplan.run_files import TRAJECTORY_FILE
from trackplan.status import Status

if TYPE_CHECKING:
    from trackplan.search import OptimizeResult


class ExitCode(enum.IntEnum):
    """Process exit codes of every command."""

    OK = 0
    INTERNAL_ERROR = 1
    BAD_INPUT = 2
    INFEASIBLE = 3
    INTERRUPTED = 130
    """Ctrl-C stopped a search (the best placement found was still planned and written) or a
    batch (pending jobs cancelled, the summary of the finished ones written)."""


def search_exit_code(result: OptimizeResult) -> ExitCode:
    """The exit code of a finished or interrupted search."""
    if result.status is Status.INTERRUPTED:
        return ExitCode.INTERRUPTED
    return ExitCode.OK if result.success else ExitCode.INFEASIBLE


PIPE_WIDTH = 160
"""Width of tables written to something other than a terminal, characters."""

DEBUG_ENV = "TRACKPLAN_DEBUG"
"""Set to 1 to print tracebacks of internal errors."""

app = typer.Typer(
    name="trackplan",
    help="Offline trajectory planning for robots following a path, with placement search.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


@app.callback()
def _options(
    debug: Annotated[
        bool,
        typer.Option("--debug", help=f"Print tracebacks of internal errors (or {DEBUG_ENV}=1)."),
    ] = False,
) -> None:
    """Offline trajectory planning for robots following a path, with placement search."""
    # main() reads --debug from the arguments itself: it must know before parsing succeeds.


def main(argv: list[str] | None = None) -> int:
    """Run the command line and return its exit code; never raises.

    Parameters
    ----------
    argv
        The arguments after the program name; ``sys.argv[1:]`` when None.

    Returns
    -------
    int
        An :class:`ExitCode` value (130 on Ctrl-C).
    """
    args = sys.argv[1:] if argv is None else list(argv)
    keep_freed_memory()
    debug = "--debug" in args or os.environ.get(DEBUG_ENV, "") not in ("", "0")
    try:
        command = typer.main.get_command(app)
        result = command.main(args=args, prog_name="trackplan", standalone_mode=False)
    except CaseError as exc:
        _error(exc.one_line())
        return ExitCode.BAD_INPUT
    except typer.TyperException as exc:
        # Usage errors (unknown option, missing argument): typer prints usage and hint.
        show = getattr(exc, "show", None)
        if callable(show):
            show()
        else:
            _error(exc.format_message())
        return exc.exit_code
    except typer.Abort:
        _error("aborted")
        return ExitCode.INTERNAL_ERROR
    except KeyboardInterrupt:
        _error("interrupted")
        return 130
    except Exception as exc:
        if debug:
            traceback.print_exc()
        _error(f"internal error: {type(exc).__name__}: {exc}".replace("\n", " "))
        return ExitCode.INTERNAL_ERROR
    return int(result) if isinstance(result, int) else ExitCode.OK


def _error(line: str) -> None:
    """One line on stderr."""
    print(line, file=sys.stderr, flush=True)


def _console() -> Console:
    """A console on the current stdout (created per command, so tests can capture it).

    Output that is not a terminal (a pipe, a file, a test) is laid out 160 columns wide
    rather than rich's 80, so that tables keep their numbers whole.
    """
    return Console(highlight=False, width=None if sys.stdout.isatty() else PIPE_WIDTH)


# --------------------------------------------------------------------------- commands


@app.command()
def validate(
    cases: Annotated[list[Path], typer.Argument(help="Case files to check.", show_default=False)],
) -> ExitCode:
    """Check case files and their robots; print a summary of each valid case."""
    loaded = _load_each(cases)
    for file, case in loaded:
        if case is not None:
            typer.echo("\n".join(describe_case(case, file)))
    return ExitCode.OK if all(case is not None for _, case in loaded) else ExitCode.BAD_INPUT


AssumeLimitsOption = Annotated[
    bool,
    typer.Option(
        "--assume-limits",
        help="For a URDF robot without acceleration/jerk limits: assume acceleration = "
        "velocity / 0.25 s and jerk = acceleration / 0.1 s (recorded in result.json).",
    ),
]


@app.command()
def robots(
    name: Annotated[
        str | None,
        typer.Argument(
            help="A built-in robot name or a robot file (.yaml/.urdf): show its chain, family "
            "and derived IK parameters.",
            show_default=False,
        ),
    ] = None,
    as_yaml: Annotated[
        str | None,
        typer.Option(
            "--yaml",
            metavar="NAME",
            help="Print the built-in DH robot NAME as a robot file, to start your own from.",
        ),
    ] = None,
    assume_limits: AssumeLimitsOption = False,
) -> ExitCode:
    """List the built-in robots (family, reach, source), or show one robot in detail."""
    from trackplan.robots.describe import robot_info

    if as_yaml is not None:
        typer.echo(robot_to_yaml(builtin_robot(as_yaml)), nl=False)
        return ExitCode.OK
    console = _console()
    if name is not None:
        robot = load_robot_spec(name, Path.cwd(), assume_limits=assume_limits)
        console.print(robot_table(robot))
        info = robot_info(robot)
        console.print(f"IK family: {info['family']}")
        for key, value in info["parameters"].items():  # type: ignore[attr-defined]
            console.print(f"  {key} = {_show_value(value)}")
        console.print(f"reach: {info['reach']:.3f} m")
        for note in robot.assumptions:
            console.print(f"assumption: {escape(note)}")
        if "redundancy_rule" in info:
            console.print(f"redundancy: {escape(str(info['redundancy_rule']))}")
        return ExitCode.OK
    table = Table(title="built-in robots (trackplan robots NAME for details)")
    for header in ("name", "joints", "family", "reach m", "source"):
        table.add_column(header, justify="left" if header in ("name", "source") else "right")
    for key in builtin_names():
        info = robot_info(builtin_robot(key))
        table.add_row(
            key,
            str(info["joints"]),
            str(info["family"]),
            f"{info['reach']:.3f}",
            escape(str(info["source"])),
        )
    console.print(table)
    return ExitCode.OK


def _show_value(value: object) -> str:
    """A parameter value for display: numbers to 6 significant digits."""
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_show_value(v) for v in value) + "]"
    return str(value)


@app.command()
def cases() -> ExitCode:
    """List the cases shipped in the repository's cases/ folder."""
    folder = shipped_cases_dir()
    files = sorted(folder.glob("*.yaml")) if folder.is_dir() else []
    if not files:
        _error(f"no shipped cases found in {folder}")
        return ExitCode.OK
    table = Table(title=f"Cases in {folder}")
    for column in ("case", "robot", "segments", "length m", "corners", "file"):
        table.add_column(column, justify="right" if column in ("segments", "length m") else "left")
    loaded = _load_each(files)
    for file, case in loaded:
        if case is None:
            table.add_row(escape(file.stem), "", "", "", "invalid", escape(file.name))
            continue
        path = NominalPath.from_specs(case.start, case.segments)
        table.add_row(
            escape(case.name),
            escape(case.robot.name),
            str(len(case.segments)),
            f"{path.length:.4f}",
            ", ".join(f"{angle:.1f}°" for _, angle in segment_corners(path)) or "none",
            escape(file.name),
        )
    _console().print(table)
    return ExitCode.OK if all(case is not None for _, case in loaded) else ExitCode.BAD_INPUT


def _load_each(files: list[Path]) -> list[tuple[Path, Case | None]]:
    """Load case files one by one; a bad one is reported on stderr and comes with None."""
    loaded: list[tuple[Path, Case | None]] = []
    for file in files:
        try:
            loaded.append((file, load_case(file)))
        except CaseError as exc:
            _error(exc.one_line())
            loaded.append((file, None))
    return loaded


# --------------------------------------------------------------------------- output


def shipped_cases_dir() -> Path:
    """The ``cases/`` folder next to the package (present in a source checkout)."""
    return Path(trackplan.__file__).resolve().parents[1] / "cases"


def describe_case(case: Case, file: Path | str) -> list[str]:
    """Summary lines of a valid case: name, robot, path length, segments, corner angles."""
    path = NominalPath.from_specs(case.start, case.segments)
    task = case.task
    corners = "; ".join(
        f"{angle:.1f}° between segments[{segment - 1}] and segments[{segment}]"
        for segment, angle in segment_corners(path)
    )
    return [
        f"{file}: ok",
        f"  name      {case.name}",
        f"  robot     {case.robot.name} ({case.robot.n_dof} joints)",
        f"  path      {_count(len(case.segments), 'segment')}, length {path.length:.4f} m",
        f"  corners   {corners or 'none'}",
        f"  task      rated speed {task.rated_speed:g} m/s, corner speed "
        f"{task.corner_speed:g} m/s, tolerance {task.tolerance * 1e3:g} mm, "
        f"sample time {task.sample_time * 1e3:g} ms, timing {task.timing}",
    ]


def segment_corners(path: NominalPath) -> list[tuple[int, float]]:
    """The corners where one segment meets the next, as the user sees them.

    Returns
    -------
    list of (int, float)
        Per corner: the index of the segment that starts there, and the angle between
        the two legs in degrees (180 for no turn; the β of the paper's Eq. 9). The turns
        between the points of one ``points`` segment are left out: they sample a curve.
    """
    owner = path.segment_index
    return [
        (int(owner[corner.junction + 1]), float(np.degrees(np.pi - corner.angle)))
        for corner in path.corners
        if owner[corner.junction] != owner[corner.junction + 1]
    ]


def robot_table(robot: Robot) -> Table:
    """A table of one robot's chain (origin and axis per joint) and joint limits."""
    from trackplan.frames import rpy_from_matrix

    table = Table(
        title=escape(f"{robot.name} ({robot.n_dof} joints)"),
        caption=escape(robot.source) or None,
    )
    headers = (
        "joint",
        "origin xyz m",
        "origin rpy °",
        "axis",
        "position °",
        "velocity rad/s",
        "acceleration rad/s²",
        "jerk rad/s³",
    )
    for header in headers:
        table.add_column(header, justify="right")

    def triple(values: np.ndarray) -> str:
        return " ".join(f"{v:.4g}" for v in np.where(np.abs(values) < 1e-12, 0.0, values))

    for i, joint in enumerate(robot.joint_names):
        origin = robot.origins[i]
        table.add_row(
            escape(joint),
            triple(origin[:3, 3]),
            triple(np.degrees(rpy_from_matrix(origin[:3, :3]))),
            triple(robot.axes[i]),
            f"[{np.degrees(robot.q_min[i]):g}, {np.degrees(robot.q_max[i]):g}]",
            f"{robot.v_max[i]:g}",
            f"{robot.a_max[i]:g}",
            f"{robot.j_max[i]:g}",
        )
    return table


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


# --------------------------------------------------------------------------- planning

PlacementOption = Annotated[
    tuple[float, float, float, float, float, float] | None,
    typer.Option(
        "--placement",
        help="X Y Z ROLL PITCH YAW of the path's frame in the robot base frame (m, rad); "
        "default: the case's placement.example.",
        show_default=False,
    ),
]
TimingOption = Annotated[
    str | None,
    typer.Option("--timing", help="smooth or paper (default: the case's task.timing)."),
]


def _placement(case: Case, values: tuple[float, ...] | None) -> np.ndarray:
    """The placement given on the command line, else the case's example placement."""
    if values is not None:
        return np.asarray(values, dtype=float)
    if case.bounds.example is None:
        raise CaseError(
            "no placement: give --placement X Y Z ROLL PITCH YAW or set placement.example",
            file=case.source,
            key="placement.example",
        )
    return np.asarray(case.bounds.example, dtype=float)


def _timing(value: str | None) -> Timing | None:
    """Validate the --timing value."""
    return None if value is None else choose(Timing, value, "--timing")


@app.command()
def plan(
    case: Annotated[Path, typer.Argument(help="Case file.", show_default=False)],
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = Path("runs/plan"),
    placement: PlacementOption = None,
    timing: TimingOption = None,
    branch: Annotated[
        int | None, typer.Option("--branch", help="Force an IK branch (closed form: 0-7).")
    ] = None,
    reference: Annotated[
        bool, typer.Option("--reference", help="Also compute toppra and TOPP3 durations.")
    ] = False,
    report: Annotated[bool, typer.Option(help="Write plots and report.html.")] = True,
    assume_limits: AssumeLimitsOption = False,
) -> ExitCode:
    """Plan the case at one placement; write trajectory.csv, result.json, plots, report."""
    from trackplan.outputs import write_run
    from trackplan.planning.plan import plan_placement

    loaded = load_case(case, assume_limits=assume_limits)
    X = _placement(loaded, placement)
    result = plan_placement(loaded, X, timing=_timing(timing), branch=branch)
    if reference and result.trajectory.n_samples:
        from trackplan.timing.references import reference_durations

        references = reference_durations(result.joint_path, loaded.task)
        result = _with_references(result, references)
    write_run(out, result, loaded, report=report)
    _print_summary(result, out)
    return ExitCode.OK if result.feasible else ExitCode.INFEASIBLE


def _with_references(result, references: dict[str, float]):
    """The result with reference durations attached."""
    from dataclasses import replace

    return replace(result, references={**result.references, **references})


@app.command()
def check(
    case: Annotated[Path, typer.Argument(help="Case file.", show_default=False)],
    run: Annotated[Path, typer.Argument(help="Folder with trajectory.csv (or the CSV itself).")],
    placement: PlacementOption = None,
    timing: TimingOption = None,
    assume_limits: AssumeLimitsOption = False,
) -> ExitCode:
    """Re-check any trajectory.csv, whoever wrote it, against the case's limits and path."""
    from trackplan.io.results import read_trajectory_csv
    from trackplan.planning.plan import check_case_trajectory

    loaded = load_case(case, assume_limits=assume_limits)
    X = _placement(loaded, placement)
    csv = run / TRAJECTORY_FILE if run.is_dir() else run
    t, q = read_trajectory_csv(csv, loaded.robot.n_dof)
    sample_time = float(np.median(np.diff(t)))
    if not np.allclose(np.diff(t), sample_time, rtol=1e-6, atol=1e-9):
        raise CaseError("samples are not evenly spaced in t", file=str(csv), key="t")
    report = check_case_trajectory(loaded, X, q, sample_time, timing=_timing(timing))
    console = _console()
    console.print(f"{escape(str(csv))}: {_count(len(t), 'sample')} at Ts = {sample_time:g} s")
    for kind, margin in report.joint_margins.items():
        cells = "  ".join(f"{m:+.3f}" for m in margin)
        console.print(f"  {kind:<13} margin per joint: {cells}")
    for kind, task_margin in report.task_margins.items():
        console.print(f"  {kind:<13} margin: {task_margin:+.3f}")
    console.print(f"  max tracking error {report.max_tracking_error * 1e3:.4f} mm")
    for violation in report.violations:
        console.print(f"  VIOLATION {escape(violation.message)}")
    count = _count(len(report.violations), "violation")
    console.print("feasible" if report.success else f"infeasible: {count}")
    return ExitCode.OK if report.success else ExitCode.INFEASIBLE


def _print_summary(result, out: Path) -> None:
    """A few lines on what a plan achieved and where its files are."""
    console = _console()
    violations = result.check.violations
    if result.feasible:
        console.print(f"{escape(result.case_name)}: {escape(result.message)}")
    elif violations:  # the list below says it all; the message would repeat its first line
        console.print(
            f"{escape(result.case_name)}: INFEASIBLE ({result.status.value}): "
            f"{_count(len(violations), 'violation')}"
        )
    else:
        console.print(
            f"{escape(result.case_name)}: INFEASIBLE ({result.status.value}): "
            f"{escape(result.message)}"
        )
    if result.trajectory.n_samples:
        console.print(
            f"  J = {result.objective:.4f}  duration = {result.duration:.3f} s  "
            f"rated speed on {100 * result.rated_speed_fraction:.1f} % of the path  "
            f"min corner speed = {result.min_corner_speed:.4f} m/s  "
            f"max tracking error = {result.check.max_tracking_error * 1e3:.4f} mm  "
            f"branch {result.branch}"
        )
        cell = result.check.cell
        if cell is not None:
            console.print(
                f"  min clearance = {1e3 * cell.min_clearance:.1f} mm "
                f"({escape(cell.closest[0])} – {escape(cell.closest[1])} at "
                f"t = {cell.t_closest:.3f} s; required {1e3 * cell.clearance:.1f} mm)"
            )
        if result.energy is not None:
            energy = result.energy
            console.print(
                f"  copper loss = {energy.copper_loss:.4g} {escape(energy.copper_loss_unit)}  "
                f"mechanical energy = {energy.mechanical_energy:.4g} J  peak torque = "
                f"{100 * energy.peak_torque_ratio:.1f} % of the limit (joint "
                f"{energy.peak_torque_joint})"
            )
        for slow in result.slowdowns:
            console.print(
                f"  slow-down: s = {slow.s_start:.4f}..{slow.s_end:.4f} m at "
                f"{slow.speed:.4f} m/s ({100 * (1 - slow.speed / slow.rated_speed):.1f} % below "
                f"rated): {escape(slow.limit)}"
            )
        for key, value in result.references.items():
            console.print(f"  {key} = {value:.4f} s")
    for violation in violations[:8]:
        console.print(f"  VIOLATION {escape(violation.message)}")
    if len(violations) > 8:
        console.print(f"  ... and {len(violations) - 8} more in result.json")
    console.print(f"  results in {escape(str(out))}/")


@app.command()
def export(
    run: Annotated[Path, typer.Argument(help="Run folder (or its trajectory.csv).")],
    format: Annotated[
        str, typer.Option("--format", help="csv, json or ros (ROS 2 JointTrajectory YAML).")
    ] = "ros",
    output: Annotated[
        Path | None,
        typer.Option("--output", help="File to write (default: next to trajectory.csv)."),
    ] = None,
    joint_names: Annotated[
        str | None,
        typer.Option(
            "--joint-names",
            help="Comma-separated joint names for the export (default: result.json's).",
        ),
    ] = None,
    frame_id: Annotated[
        str, typer.Option("--frame-id", help="header.frame_id of the ROS message.")
    ] = "",
) -> ExitCode:
    """Export a run's trajectory as CSV, JSON or a ROS 2 trajectory_msgs/JointTrajectory."""
    from trackplan.io.export import export_trajectory

    names = [name.strip() for name in joint_names.split(",")] if joint_names else None
    written = export_trajectory(run, format, output, joint_names=names, frame_id=frame_id)
    typer.echo(f"wrote {written}")
    return ExitCode.OK


# --------------------------------------------------------------------------- placement search


@app.command()
def optimize(
    case: Annotated[Path, typer.Argument(help="Case file.", show_default=False)],
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = Path("runs/optimize"),
    method: Annotated[
        str | None,
        typer.Option("--method", help="ga, cmaes, de or random (default: optimizer.method)."),
    ] = None,
    seed: Annotated[
        int | None, typer.Option("--seed", help="Random seed (default: optimizer.seed).")
    ] = None,
    budget: Annotated[
        int | None,
        typer.Option("--budget", help="Largest number of placement evaluations."),
    ] = None,
    restarts: Annotated[
        int | None,
        typer.Option(
            "--restarts",
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
    ``initial`` blocks, plots and report.html unless --no-report) plus history.csv. Ctrl-C
    stops the search and still writes everything for the best placement found.
    """
    from trackplan.outputs import write_search_run

    loaded = load_case(case, assume_limits=assume_limits)
    if objective is not None:
        from trackplan.planning.objectives import with_objective

        loaded = with_objective(loaded, objective)
    if pareto is not None:
        return _pareto(loaded, pareto, out, seed=seed, timing=_timing(timing), report=report)
    result = _search(
        loaded, method=method, seed=seed, budget=budget, restarts=restarts, timing=_timing(timing)
    )
    write_search_run(out, result, loaded, report=report)
    _print_search(result, out)
    return search_exit_code(result)


@app.command()
def demo(
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = Path("runs/demo"),
) -> ExitCode:
    """Optimize the paper's corner case (cases/paper-corner.yaml) end to end, with the report."""
    file = shipped_cases_dir() / "paper-corner.yaml"
    if not file.is_file():
        raise CaseError("the shipped demo case is missing (run from a source checkout)", str(file))
    from trackplan.outputs import write_search_run

    loaded = load_case(file)
    result = _search(loaded)
    write_search_run(out, result, loaded, report=True)
    _print_search(result, out)
    typer.echo(f"report: {(out / 'report.html').resolve()}")
    return search_exit_code(result)


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
        int, typer.Option("--points", min=2, help="Grid points along x and along y.")
    ] = 41,
) -> ExitCode:
    """Map feasibility (reach, joint limit, collision) and J over an x-y grid of placements.

    Writes map.png, map.csv and map.html. Without --rpy and --z the case's placement
    search runs first and the map keeps its best placement's height and orientation.
    """
    from trackplan.io.map_file import write_map_csv
    from trackplan.report.cell_figures import write_map_report
    from trackplan.search.placement_map import placement_map

    loaded = load_case(case)
    reference = np.full(6, np.nan)  # x, y stay unset unless the search ran
    if rpy is None or z is None:
        reference = np.asarray(_search(loaded).X, dtype=float)
    if z is not None:
        reference[2] = z
    if rpy is not None:
        reference[3:] = rpy
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
    console = _console()
    console.print(f"{escape(result.message)}, {result.wall_time_s:.2f} s (seed {result.seed})")
    a, b = result.objectives
    for row in rows:
        state = "feasible" if row["feasible"] else "INFEASIBLE"
        console.print(f"  {row['point']:>2}  {a} {row[a]:.4g}  {b} {row[b]:.4g}  {state}")
    console.print(f"  results in {escape(str(out))}/")
    return ExitCode.OK if result.success else ExitCode.INFEASIBLE


def _search(case: Case, **options):  # type: ignore[no-untyped-def]
    """Run the placement search, with a progress bar when stderr is a terminal."""
    from rich.progress import Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

    from trackplan.search import optimize_placement

    console = Console(stderr=True)
    if not console.is_terminal:
        return optimize_placement(case, **options)
    columns = (SpinnerColumn(), TextColumn("{task.description}"), TimeElapsedColumn())
    with Progress(*columns, console=console, transient=True) as bar:
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
            )

        return optimize_placement(case, progress=show, **options)


def _print_search(result, out: Path) -> None:  # type: ignore[no-untyped-def]
    """The search summary, then the final plan's summary."""
    console = _console()
    initial = result.initial
    before = (
        f"J = {initial.objective:.4f}"
        if initial.feasible
        else f"infeasible ({initial.status.value})"
    )
    console.print(
        f"{escape(result.method)} (seed {result.seed}): {result.evaluations} evaluations in "
        f"{_count(result.generations, 'generation')} over {_count(result.runs, 'run')}, "
        f"{result.wall_time_s:.2f} s, "
        f"last run stopped: {escape(result.stop_reason)}"
    )
    console.print(f"  before (centre of the bounds, X = {_vector(initial.placement)}): {before}")
    after = (
        escape(result.message)
        if result.success
        else f"no feasible placement in {_count(result.evaluations, 'evaluation')}; "
        "the closest one is planned below"
    )
    console.print(f"  after  (X = {_vector(result.X)}): {after}")
    _print_summary(result.final, out)


def _vector(values: np.ndarray) -> str:
    return "(" + ", ".join(f"{v:.4f}" for v in values) + ")"


# --------------------------------------------------------------------------- batch studies


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
    from trackplan.io.study_file import load_study
    from trackplan.study import connect, run_study

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
            client.close()
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
                    f"[{state.done}/{state.total}] {row.job}: {row.status} "
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
