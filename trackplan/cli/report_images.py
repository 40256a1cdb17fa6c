"""``trackplan report``: a run's report rewritten from its folder, or its still images."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from trackplan.cli import ExitCode
from trackplan.cli.common import app, console, output_folder
from trackplan.errors import CaseError


@app.command()
def report(
    run: Annotated[Path, typer.Argument(help="Run folder (or its trajectory.csv).")],
    png: Annotated[
        bool,
        typer.Option("--png", help="Write the 3D view and every plot as PNG (headless Chromium)."),
    ] = False,
    out: Annotated[
        Path | None,
        typer.Option("--out", help="With --png: the images' folder (default: RUN/images)."),
    ] = None,
    case: Annotated[
        Path | None,
        typer.Option("--case", help="The case file of the run (default: result.json's)."),
    ] = None,
) -> ExitCode:
    """Rewrite a run's report from its folder, or with --png write its 3D view and plots.

    The run is planned again and must reproduce trajectory.csv, as for export (results.md).
    """
    from trackplan.report.images import chromium, report_images, rewrite_report

    if out is not None and not png:
        raise CaseError("names the images' folder: add --png", key="--out")
    if png:
        if out is not None:
            output_folder(out)
        chromium()  # before any work: say what to install
        written = report_images(run, out, case=case)
        for path in written:
            console().print(f"wrote {path}", highlight=False, soft_wrap=True)
        return ExitCode.OK
    page = rewrite_report(run, case)
    console().print(f"wrote {page}", highlight=False, soft_wrap=True)
    return ExitCode.OK
