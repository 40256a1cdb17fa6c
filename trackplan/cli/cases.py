"""Commands on inputs: ``validate`` (case files), ``robots`` (built-in robots), ``cases``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape
from rich.table import Table

from trackplan.cli import ExitCode
from trackplan.cli.common import app, console, error, load_each, shipped_cases_dir
from trackplan.cli.summaries import describe_case, robot_table, segment_corners
from trackplan.io.robot_file import robot_to_yaml
from trackplan.paths import NominalPath
from trackplan.robots.builtin import BUILTIN_ROBOTS, builtin_robot


@app.command()
def validate(
    cases: Annotated[list[Path], typer.Argument(help="Case files to check.", show_default=False)],
) -> ExitCode:
    """Check case files and their robots; print a summary of each valid case."""
    loaded = load_each(cases)
    for file, case in loaded:
        if case is not None:
            typer.echo("\n".join(describe_case(case, file)))
    return ExitCode.OK if all(case is not None for _, case in loaded) else ExitCode.BAD_INPUT


@app.command()
def robots(
    as_yaml: Annotated[
        str | None,
        typer.Option(
            "--yaml",
            metavar="NAME",
            help="Print the built-in robot NAME as a robot file, to start your own from.",
        ),
    ] = None,
) -> ExitCode:
    """Show the built-in robots and their limits."""
    if as_yaml is not None:
        typer.echo(robot_to_yaml(builtin_robot(as_yaml)), nl=False)
        return ExitCode.OK
    out = console()
    for name in sorted(BUILTIN_ROBOTS):
        out.print(robot_table(builtin_robot(name)))
    return ExitCode.OK


@app.command()
def cases() -> ExitCode:
    """List the cases shipped in the repository's cases/ folder."""
    folder = shipped_cases_dir()
    files = sorted(folder.glob("*.yaml")) if folder.is_dir() else []
    if not files:
        error(f"no shipped cases found in {folder}")
        return ExitCode.OK
    table = Table(title=f"Cases in {folder}")
    for column in ("case", "robot", "segments", "length m", "corners", "file"):
        table.add_column(column, justify="right" if column in ("segments", "length m") else "left")
    loaded = load_each(files)
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
    console().print(table)
    return ExitCode.OK if all(case is not None for _, case in loaded) else ExitCode.BAD_INPUT
