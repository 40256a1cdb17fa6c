"""``part.html``: a part's CAD model in 3D, every face and edge id on hover (``trackplan part``).

The faces are the part's tessellation (one colour per face), the edges the polylines of
:meth:`~trackplan.cad.part.PartModel.edge_points`; hovering a triangle names its face (id,
kind, area), hovering an edge names it (id, kind, length, the faces it joins) and gives the
point under the cursor in metres, so a user can find the ids or the ``near`` points a case's
``cad`` seams name (``docs/cad.md``).
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import Any

import numpy as np

from trackplan.cad.part import PartModel
from trackplan.report.plotly_html import plotly_div

CHORD_FRACTION = 2e-3
"""The chord error of the drawing, as a fraction of the part's largest extent."""


def part_figure(part: PartModel) -> dict[str, Any]:
    """The plotly figure (plain data): a Mesh3d of the faces and a Scatter3d of the edges."""
    chord = max(_extent(part) * CHORD_FRACTION, 1e-6)
    mesh = part.tessellation(chord)
    faces = {f.id: f for f in part.faces}
    vertex_face = np.zeros(len(mesh.vertices), dtype=int)  # a vertex's (last) face
    if len(mesh.face):
        vertex_face[mesh.triangles.ravel()] = np.repeat(mesh.face, 3)
    text = [
        f"face {i}: {faces[i].kind}, {faces[i].area:.6g} m²" if i in faces else ""
        for i in vertex_face.tolist()
    ]
    golden = 0.618033988749895
    colors = [f"hsl({int(360 * ((i * golden) % 1.0))},55%,62%)" for i in mesh.face.tolist()]
    surface = {
        "type": "mesh3d",
        "name": "faces",
        "x": mesh.vertices[:, 0].tolist(),
        "y": mesh.vertices[:, 1].tolist(),
        "z": mesh.vertices[:, 2].tolist(),
        "i": mesh.triangles[:, 0].tolist(),
        "j": mesh.triangles[:, 1].tolist(),
        "k": mesh.triangles[:, 2].tolist(),
        "facecolor": colors,
        "flatshading": True,
        "text": text,
        "hovertemplate": "%{text}<br>x %{x:.4f}, y %{y:.4f}, z %{z:.4f} m<extra></extra>",
    }
    xs: list[float | None] = []
    ys: list[float | None] = []
    zs: list[float | None] = []
    labels: list[str] = []
    for edge in part.edges:
        if edge.length <= 0:
            continue
        points = part.edge_points(edge.id, chord)
        label = f"edge {edge.id}: {edge.kind}, {edge.length:.6g} m, faces " + ", ".join(
            str(i) for i in edge.faces
        )
        xs += [*points[:, 0].tolist(), None]
        ys += [*points[:, 1].tolist(), None]
        zs += [*points[:, 2].tolist(), None]
        labels += [label] * len(points) + [""]
    lines = {
        "type": "scatter3d",
        "mode": "lines",
        "name": "edges",
        "x": xs,
        "y": ys,
        "z": zs,
        "text": labels,
        "line": {"color": "#222", "width": 4},
        "hovertemplate": "%{text}<br>x %{x:.4f}, y %{y:.4f}, z %{z:.4f} m<extra></extra>",
    }
    layout = {
        "height": 720,
        "margin": {"l": 0, "r": 0, "t": 30, "b": 0},
        "title": {
            "text": f"{Path(part.source).name}: {len(part.faces)} faces, "
            f"{len(part.edges)} edges (hover for ids)"
        },
        "scene": {
            "aspectmode": "data",
            "xaxis": {"title": {"text": "x m"}},
            "yaxis": {"title": {"text": "y m"}},
            "zaxis": {"title": {"text": "z m"}},
        },
        "showlegend": True,
    }
    return {"data": [surface, lines], "layout": layout}


def _extent(part: PartModel) -> float:
    """The part's largest extent, m, from its faces' centroids and its edges' ends."""
    points = np.array(
        [f.centroid for f in part.faces] + [p for e in part.edges for p in (e.start, e.end)]
    ).reshape(-1, 3)
    if not len(points):
        return 1.0
    return float(np.max(points.max(axis=0) - points.min(axis=0))) or 1.0


def write_part_html(part: PartModel, path: Path) -> Path:
    """Write ``part.html`` (self-contained, works offline) and return its path."""
    title = html.escape(f"{Path(part.source).name}: faces and edges")
    page = (
        "<!DOCTYPE html>\n<html><head><meta charset='utf-8'>"
        f"<title>{title}</title></head><body>"
        f"<p>{html.escape(part.source)}: hover a face or an edge for its id; the points are in "
        "metres, in the part's frame.</p>"
        f"{plotly_div(part_figure(part), 'part')}</body></html>\n"
    )
    path = Path(path)
    path.write_text(page, encoding="utf-8")
    return path
