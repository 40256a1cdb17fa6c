"""Commands on inputs: ``validate`` (case files), ``seams`` (a case's CAD seams as plain
segments), ``robots`` (built-in robots), ``positioners`` (built-in positioners), ``cases``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from trackplan.cli import ExitCode
from trackplan.cli.common import (
    AssumeLimitsOption,
    app,
    console,
    error,
    load_each,
    shipped_cases_dir,
)


@app.command()
def validate(
    cases: Annotated[list[Path], typer.Argument(help="Case files to check.", show_default=False)],
    assume_limits: AssumeLimitsOption = False,
) -> ExitCode:
    """Check case files and their robots; print a summary of each valid case."""
    from trackplan.cli.summaries import describe_case
    from trackplan.io.case_cad import describe_cad, load_cad

    loaded = load_each(cases, assume_limits=assume_limits)
    for file, case in loaded:
        if case is not None:
            typer.echo("\n".join(describe_case(case, file)))
            cad = load_cad(file)[1] if case.source is not None else None
            if cad is not None:
                typer.echo("\n".join(describe_cad(cad)))
    return ExitCode.OK if all(case is not None for _, case in loaded) else ExitCode.BAD_INPUT


@app.command()
def seams(
    case: Annotated[Path, typer.Argument(help="A case file with cad: seams.", show_default=False)],
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            help="The case file to write: every seam as plain segments with its weld normals "
            "(write it beside the case: relative file names are kept).",
            show_default=False,
        ),
    ],
    assume_limits: AssumeLimitsOption = False,
) -> ExitCode:
    """Derive the seams of a case's part (paths[i].cad) and write the case with them as
    plain segments, for a user to inspect or edit (docs/cad.md)."""
    from trackplan.io.case_cad import describe_cad, load_cad, plain_case_yaml
    from trackplan.io.case_file import load_case
    from trackplan.io.run_folder import write_atomically

    load_case(case, assume_limits=assume_limits)  # the whole case is valid
    data, cad = load_cad(case)
    if cad is None or not cad.paths:
        error(f"{case}: no paths[i].cad seams to derive (docs/cad.md)")
        return ExitCode.BAD_INPUT
    if out.resolve() == case.resolve() or not out.parent.is_dir():
        problem = "is the case itself" if out.parent.is_dir() else "is in no existing folder"
        error(f"--out {out} {problem}: name a new file beside the case")
        return ExitCode.BAD_INPUT
    text = plain_case_yaml(data)

    def write(path: Path) -> None:
        path.write_text(text, encoding="utf-8")

    write_atomically(out, write)
    typer.echo("\n".join([*describe_cad(cad), f"wrote {out}"]))
    return ExitCode.OK


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
    """List the built-in robots (family, reach, link capsules, source), or show one robot."""
    from rich.markup import escape
    from rich.table import Table

    from trackplan.cell.robot_bodies import link_capsules_line
    from trackplan.cli.summaries import robot_table
    from trackplan.io.robot_file import builtin_names, builtin_robot, load_robot_spec, robot_to_yaml
    from trackplan.robots.describe import robot_info

    if as_yaml is not None:
        typer.echo(robot_to_yaml(builtin_robot(as_yaml)), nl=False)
        return ExitCode.OK
    out = console()
    if name is not None:
        robot = load_robot_spec(name, Path.cwd(), assume_limits=assume_limits)
        out.print(robot_table(robot))
        info = robot_info(robot)
        out.print(f"IK family: {info['family']}")
        for key, value in info["parameters"].items():  # type: ignore[attr-defined]
            out.print(f"  {key} = {_show_value(value)}")
        out.print(f"reach: {info['reach']:.3f} m")
        out.print(link_capsules_line(robot))
        for note in robot.assumptions:
            out.print(f"assumption: {escape(note)}")
        redundancy = info.get("redundancy")
        if isinstance(redundancy, dict):
            low, high = redundancy["range"]
            out.print(
                f"redundancy: the {redundancy['parameter']} in [{low:.4f}, {high:.4f}] rad, "
                "chosen along each seam (task.redundancy)"
            )
        if "redundancy_rule" in info:
            out.print(f"redundancy: {escape(str(info['redundancy_rule']))}")
        return ExitCode.OK
    table = Table(title="built-in robots (trackplan robots NAME for details)")
    for header in ("name", "joints", "family", "reach m", "capsules", "source"):
        table.add_column(header, justify="left" if header in ("name", "source") else "right")
    for key in builtin_names():
        info = robot_info(builtin_robot(key))
        table.add_row(
            key,
            str(info["joints"]),
            str(info["family"]),
            f"{info['reach']:.3f}",
            str(info["link_capsules"]),
            escape(str(info["source"])),
        )
    out.print(table)
    return ExitCode.OK


@app.command()
def positioners(
    name: Annotated[
        str | None,
        typer.Argument(
            help="A built-in positioner name or a positioner file (.yaml): show its axes, "
            "limits, flange and assumptions.",
            show_default=False,
        ),
    ] = None,
    assume_limits: AssumeLimitsOption = False,
) -> ExitCode:
    """List the built-in positioners (axes, ranges, speeds, assumed acceleration and jerk,
    source), or show one positioner (docs/positioner.md)."""
    from rich.markup import escape
    from rich.table import Table

    from trackplan.cell.robot_bodies import link_capsules_line
    from trackplan.cli.summaries import robot_table
    from trackplan.frames import rpy_from_matrix
    from trackplan.io.positioner_file import (
        builtin_positioner,
        load_positioner_spec,
        positioner_names,
    )

    out = console()
    if name is not None:
        chain = load_positioner_spec(name, Path.cwd(), case_file=None, assume_limits=assume_limits)
        out.print(robot_table(chain))
        xyz = " ".join(f"{v:.4g}" for v in chain.T_tip[:3, 3])
        rpy = " ".join(f"{v + 0.0:.4g}" for v in rpy_from_matrix(chain.T_tip[:3, :3]))
        out.print(f"flange (carrier frame) from the last axis: xyz {xyz} m, rpy {rpy} rad")
        out.print(link_capsules_line(chain))
        for note in chain.assumptions:
            out.print(f"assumption: {escape(note)}")
        return ExitCode.OK
    import numpy as np

    table = Table(title="built-in positioners (trackplan positioners NAME for details)")
    headers = ("name", "axes", "range °", "speed °/s", "accel. rad/s²", "jerk rad/s³", "source")
    for header in headers:
        table.add_column(header, justify="left" if header in ("name", "source") else "right")
    for key in positioner_names():
        chain = builtin_positioner(key)

        def each(values: object, digits: str = "g") -> str:
            return ", ".join(f"{v:{digits}}" for v in values)  # type: ignore[attr-defined]

        ranges = zip(np.degrees(chain.q_min), np.degrees(chain.q_max), strict=True)
        table.add_row(
            key,
            ", ".join(chain.joint_names),
            ", ".join(f"[{low:.0f}, {high:.0f}]" for low, high in ranges),
            each(np.degrees(chain.v_max), ".0f"),
            each(chain.a_max, ".4g"),
            each(chain.j_max, ".4g"),
            escape(chain.source),
        )
    out.print(table)
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
    """List the cases shipped in the repository's cases/ folder: a row per case (its seams'
    segments and lengths summed), then a row per seam (segments, length, corners)."""
    from rich.markup import escape
    from rich.table import Table

    from trackplan.cli.summaries import segment_corners
    from trackplan.paths import NominalPath

    folder = shipped_cases_dir()
    files = sorted(folder.glob("*.yaml")) if folder.is_dir() else []
    if not files:
        error(f"no shipped cases found in {folder}")
        return ExitCode.OK
    table = Table(title=f"Cases in {folder}")
    numbers = ("seams", "segments", "length m")
    for column in ("case", "robot", *numbers, "corners", "file"):
        table.add_column(column, justify="right" if column in numbers else "left")
    loaded = load_each(files)
    for file, case in loaded:
        if case is None:
            table.add_row(escape(file.stem), "", "", "", "", "invalid", escape(file.name))
            continue
        seams = [(seam, NominalPath.from_specs(seam.start, seam.segments)) for seam in case.seams]

        def corners(path: NominalPath) -> str:
            return ", ".join(f"{angle:.1f}°" for _, angle in segment_corners(path)) or "none"

        table.add_row(
            escape(case.name),
            escape(case.robot.name),
            str(len(seams)),
            str(sum(len(seam.segments) for seam, _ in seams)),
            f"{sum(path.length for _, path in seams):.4f}",
            "per seam below",
            escape(file.name),
        )
        for seam, path in seams:
            table.add_row(
                f"· {escape(seam.name)}",
                "",
                "",
                str(len(seam.segments)),
                f"{path.length:.4f}",
                corners(path),
                "",
            )
    console().print(table)
    return ExitCode.OK if all(case is not None for _, case in loaded) else ExitCode.BAD_INPUT
