"""Commands on one placement: ``plan``, ``check`` (any trajectory.csv) and ``export``."""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path
from typing import Annotated, Any

import typer
from typer.core import TyperCommand

from trackplan.cli import ExitCode
from trackplan.cli.common import (
    AssumeLimitsOption,
    PlacementOption,
    TimingOption,
    app,
    check_sample_times,
    console,
    output_folder,
    placement,
    placement_option,
    run_placement,
    run_positioner,
    timing_option,
)
from trackplan.errors import CaseError


@app.command()
def plan(
    case: Annotated[Path, typer.Argument(help="Case file.", show_default=False)],
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = Path("runs/plan"),
    placement_values: PlacementOption = None,
    timing: TimingOption = None,
    branch: Annotated[
        int | None,
        typer.Option("--branch", min=0, help="Force an IK branch (closed form: 0-7)."),
    ] = None,
    reference: Annotated[
        bool, typer.Option("--reference", help="Also compute toppra and TOPP3 durations.")
    ] = False,
    report: Annotated[bool, typer.Option(help="Write plots and report.html.")] = True,
    assume_limits: AssumeLimitsOption = False,
    spin: Annotated[
        float | None, typer.Option("--spin", help="Constant spin about the tool axis, rad.")
    ] = None,
    spin_profile: Annotated[
        Path | None,
        typer.Option("--spin-profile", help="Spin profile file (or a result.json), rad."),
    ] = None,
) -> ExitCode:
    """Plan the case at one placement; write trajectory.csv, result.json, plots, report.

    With a free spin and neither --spin nor --spin-profile, the spin is optimised for the
    placement (docs/tool.md).
    """
    import numpy as np

    from trackplan.cli.summaries import print_plan
    from trackplan.io.case_file import load_case
    from trackplan.outputs import write_run
    from trackplan.planning.plan import plan as plan_case
    from trackplan.search.spin import optimize_spin
    from trackplan.tool import SpinProfile

    out = output_folder(out)
    X_given = placement_option(placement_values)
    timing = timing_option(timing)
    loaded = load_case(case, assume_limits=assume_limits)
    X = placement(loaded, X_given)
    if spin is not None and spin_profile is not None:
        raise CaseError("give --spin or --spin-profile, not both", key="--spin")
    given = None
    if spin is not None:
        given = SpinProfile(np.array([spin]), 0.0)
    elif spin_profile is not None:
        from trackplan.io.tool_file import load_spin_profile

        given = load_spin_profile(spin_profile)
    if given is None and loaded.task.tool.n_spin and branch is None and len(loaded.seams) == 1:
        result = optimize_spin(loaded, X, timing=timing)
    else:
        result = plan_case(loaded, X, timing=timing, branch=branch, spin=given)
    if reference and result.trajectory.n_samples:
        from trackplan.timing.references import reference_durations

        references = reference_durations(result.joint_path, loaded.task)
        result = replace(result, references={**result.references, **references})
    write_run(out, result, loaded, report=report)
    print_plan(console(), result, out, rated_speed=loaded.task.rated_speed)
    return ExitCode.OK if result.feasible else ExitCode.INFEASIBLE


@app.command()
def check(
    case: Annotated[Path, typer.Argument(help="Case file.", show_default=False)],
    run: Annotated[Path, typer.Argument(help="Run folder (or any trajectory CSV file).")],
    placement_values: PlacementOption = None,
    timing: TimingOption = None,
    assume_limits: AssumeLimitsOption = False,
) -> ExitCode:
    """Re-check any trajectory.csv, whoever wrote it, against the case's limits and path.

    A run folder must be consistent (its result.json written with its trajectory.csv) and
    is checked at the placement its result.json records unless --placement is given; a
    CSV file is read as it is, columns t and q1..qn found by their header names. Its
    samples must be the case's: t = k · task.sample_time from t = 0.
    """
    from trackplan.cli.summaries import print_check
    from trackplan.io.case_file import load_case
    from trackplan.io.results import read_segments, read_trajectory_csv
    from trackplan.io.run_folder import verified_trajectory
    from trackplan.planning.plan import check as check_case

    X_given = placement_option(placement_values)
    timing = timing_option(timing)
    loaded = load_case(case, assume_limits=assume_limits)
    csv = verified_trajectory(run)
    X = placement(loaded, X_given if X_given is not None else run_placement(run))
    loaded = run_positioner(loaded, run)
    t, q = read_trajectory_csv(csv, loaded.machine.n_dof)
    sample_time = loaded.task.sample_time
    check_sample_times(t, sample_time, str(csv))
    segment = read_segments(csv)
    report = check_case(loaded, X, q, sample_time, timing=timing, segment=segment)
    print_check(console(), str(csv), len(t), sample_time, report)
    return ExitCode.OK if report.success else ExitCode.INFEASIBLE


class _ExportCommand(TyperCommand):
    """``export``: its ``--format`` help lists the registered writers when help is shown
    (building it at import would import the writers before any command runs)."""

    def format_help(self, ctx: Any, formatter: Any) -> None:
        """Fill in the formats, then format the help as typer does."""
        from trackplan.writers import WRITERS

        for param in self.params:
            if param.name == "format":
                param.help = f"One of {', '.join(WRITERS)}."  # type: ignore[attr-defined]
        super().format_help(ctx, formatter)


@app.command(cls=_ExportCommand)
def export(
    run: Annotated[Path, typer.Argument(help="Run folder (or its trajectory.csv).")],
    format: Annotated[str, typer.Option("--format", help="A registered export format.")] = "ros",
    motion: Annotated[
        str,
        typer.Option(
            "--motion",
            help="Programs: cartesian (the seams in path moves) or joint (the samples).",
        ),
    ] = "cartesian",
    name: Annotated[
        str | None, typer.Option("--name", help="Program name (default: the case's).")
    ] = None,
    output: Annotated[
        Path | None,
        typer.Option(
            "--output",
            help="File to write, or for a program of several files the folder "
            "(default: next to trajectory.csv).",
        ),
    ] = None,
    period: Annotated[
        float | None,
        typer.Option(
            "--period", help="Programs, --motion joint: s between targets, a multiple of Ts."
        ),
    ] = None,
    max_points: Annotated[
        int | None,
        typer.Option(
            "--max-points", help="Programs: most points per part, >= 2 (default: the format's)."
        ),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="Programs: write an infeasible run too.")
    ] = False,
    case: Annotated[
        Path | None,
        typer.Option("--case", help="Programs: the case file of the run (default: result.json's)."),
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
    """Export a run: its trajectory (CSV, JSON, ROS 2 JointTrajectory) or a robot program.

    The program formats plan the run's case again at the run's placement and check that
    the plan reproduces trajectory.csv before they write (docs/export.md).
    """
    from trackplan.programs.model import MOTION_FORMS
    from trackplan.writers import export_files

    if motion not in MOTION_FORMS:
        raise CaseError(
            f"unknown motion {motion!r}: use {' or '.join(MOTION_FORMS)}", key="--motion"
        )
    if max_points is not None and max_points < 2:
        raise CaseError(f"must be at least 2 points, got {max_points}", key="--max-points")
    if output is not None and not output.is_dir():
        output_folder(output.parent, "--output")
    names = [joint.strip() for joint in joint_names.split(",")] if joint_names else None
    written = export_files(
        run,
        output,
        format=format,
        joint_names=names,
        case=case,
        frame_id=frame_id,
        motion=motion,
        name=name,
        period=period,
        max_points=max_points,
        force=force,
    )
    for line in _written_lines(written):
        typer.echo(line)
    return ExitCode.OK


SHOWN_FILES = 4
"""Files ``export`` names one per line; more are summed up in one line."""


def _written_lines(written: tuple[Path, ...]) -> list[str]:
    """``wrote <path>`` per file; of a program split into many parts, the first two files
    (the main program and its data) and one line for the rest (their count, folder and
    first and last names)."""
    if len(written) <= SHOWN_FILES:
        return [f"wrote {file}" for file in written]
    rest = written[2:]
    return [
        *(f"wrote {file}" for file in written[:2]),
        f"wrote {len(rest)} more files in {rest[0].parent}{os.sep} "
        f"({rest[0].name} … {rest[-1].name})",
    ]
