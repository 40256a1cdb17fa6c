"""The ``part`` command: list a part's faces and edges (``docs/cad.md``)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from trackplan.cli import ExitCode
from trackplan.cli.common import app, console, output_folder

if TYPE_CHECKING:
    from trackplan.cad.part import PartModel


@app.command()
def part(
    file: Annotated[
        Path,
        typer.Argument(
            help="A part's CAD file: STEP (.step/.stp) or a mesh (.stl/.obj/.ply).",
            show_default=False,
        ),
    ],
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the faces and edges as JSON instead.")
    ] = False,
    out: Annotated[
        Path | None,
        typer.Option(
            help="Also write DIR/part.html: the part in 3D, ids on hover.",
            metavar="DIR",
            show_default=False,
        ),
    ] = None,
    scale: Annotated[
        float | None,
        typer.Option(help="A mesh's file units to metres (e.g. 0.001 for mm).", show_default=False),
    ] = None,
) -> ExitCode:
    """List a part's faces (id, kind, area, centroid, normal or axis) and edges (id, kind,
    length, ends, faces), the ids and points a case's ``cad`` seams name."""
    from trackplan.io.part_file import load_part

    folder = output_folder(out) if out is not None else None
    model = load_part(file, scale=scale)
    if as_json:
        typer.echo(json.dumps(part_listing(model), indent=1))
    else:
        _print_tables(model)
    if folder is not None:
        from trackplan.report.part_view import write_part_html

        folder.mkdir(parents=True, exist_ok=True)
        written = write_part_html(model, folder / "part.html")
        typer.echo(f"wrote {written}", err=as_json)
    return ExitCode.OK


def _vector(value: Any) -> list[float] | None:
    return None if value is None else [float(v) for v in value]


def part_listing(model: PartModel) -> dict[str, Any]:
    """The part's faces and edges as JSON-ready data (metres, m²)."""
    return {
        "source": model.source,
        "exact": model.exact,
        "faces": [
            {
                "id": f.id,
                "kind": f.kind,
                "area": f.area,
                "centroid": _vector(f.centroid),
                "normal": _vector(f.normal),
                "axis": _vector(f.axis),
            }
            for f in model.faces
        ],
        "edges": [
            {
                "id": e.id,
                "kind": e.kind,
                "length": e.length,
                "start": _vector(e.start),
                "end": _vector(e.end),
                "faces": list(e.faces),
            }
            for e in model.edges
        ],
    }


def _print_tables(model: PartModel) -> None:
    from rich.markup import escape
    from rich.table import Table

    def xyz(value: Any) -> str:
        return "" if value is None else " ".join(f"{round(float(v), 4) + 0.0:.4f}" for v in value)

    out = console()
    kind = "exact B-rep" if model.exact else "mesh: positions as good as its triangles"
    faces = Table(title=f"faces of {escape(model.source)} ({kind}; m, m²)")
    for header in ("face", "kind", "area m²", "centroid m", "normal / axis"):
        faces.add_column(header, justify="right" if header in ("face", "area m²") else "left")
    for f in model.faces:
        direction = f"normal {xyz(f.normal)}" if f.normal is not None else ""
        if f.axis is not None:
            direction = f"axis {xyz(f.axis)}"
        faces.add_row(str(f.id), f.kind, f"{f.area:.6g}", xyz(f.centroid), direction)
    out.print(faces)
    edges = Table(title="edges (ends in the edge's own direction)")
    for header in ("edge", "kind", "length m", "start m", "end m", "faces"):
        edges.add_column(header, justify="right" if header in ("edge", "length m") else "left")
    for e in model.edges:
        edges.add_row(
            str(e.id),
            e.kind + (" (closed)" if e.closed and e.length > 0 else ""),
            f"{e.length:.6g}",
            xyz(e.start),
            xyz(e.end),
            ", ".join(str(i) for i in e.faces),
        )
    out.print(edges)
