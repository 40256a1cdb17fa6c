"""The robot as it looks in the 3D view: its URDF meshes, else solids from its capsules.

:func:`robot_look` picks the robot's look, most faithful first:

- **meshes**: the robot's visual meshes (:attr:`~trackplan.robots.model.Robot.visuals`,
  read from a URDF's ``<visual>`` elements), one mesh3d trace per colour, decimated so that
  their animation fits :data:`MESH_PAGE_BYTES` of the page and at most
  :data:`~trackplan.robots.visuals.MAX_TRIANGLES` triangles;
- **capsules**: shaded solids of the link capsules (the cell's ``links`` in a cell case,
  else the robot's own) and, in a cell case, the tool's capsules;
- **lines**: a robot with neither is drawn by the view as a thick line through its
  frames, and the legend says so.

Each part is fixed in a chain frame, so its vertices in every animation frame are one
matrix product with that frame's pose (no loop over samples).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from trackplan.case import Case
from trackplan.robots.collision import Capsules
from trackplan.robots.visuals import MAX_TRIANGLES, LinkVisual, decimate_visuals

TraceBuilder = Callable[[int], dict]

MESH_PAGE_BYTES = 3_000_000
"""Most bytes the robot's animated meshes take in the page (all frames)."""
SOLID_DECIMALS = 3
"""Decimals of the solids' coordinates, m (1 mm: they are sent in every frame)."""
BYTES_PER_VERTEX = 3 * 8
"""Bytes of one vertex in one frame, at most (``-0.123,`` per coordinate, and the rest of
the trace)."""
MESHES_TRACE = "robot (URDF meshes)"
"""Name of the first mesh trace; the others are named after their links."""
SOLIDS_TRACE = "robot (link capsules)"
TOOL_SOLIDS_TRACE = "tool (capsules)"
CAPSULES_TRACE = "link capsules"
"""The checked capsules, drawn see-through beside the meshes in a cell case."""
LINES_NOTE = "robot drawn as lines: it has no meshes or link capsules"
LINK_COLOR = "#7d93b8"
TOOL_COLOR = "#e07b39"


@dataclass
class RobotLook:
    """The traces of the robot's look.

    Attributes
    ----------
    kind
        ``"meshes"``, ``"capsules"`` or ``"lines"`` (then there are no builders: the view
        draws the frames' chain as a thick line).
    builders
        Builders of the animated traces, each taking the animation frame's index.
    points
        Every vertex drawn over all frames, shape (M, 3), m (for the view's limits).
    triangles
        Triangles drawn per frame.
    """

    kind: str
    builders: list[TraceBuilder] = field(default_factory=list)
    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    triangles: int = 0


@dataclass(frozen=True)
class _Part:
    """A mesh fixed in chain frame ``frame``: vertices (V, 3) in that frame, faces (T, 3)."""

    frame: int
    vertices: np.ndarray
    faces: np.ndarray


def mesh_budget(n_frames: int, page_bytes: int = MESH_PAGE_BYTES) -> int:
    """Most triangles of the robot's meshes in a view of ``n_frames`` animation frames:
    :data:`MAX_TRIANGLES`, and no more than ``page_bytes`` of vertices over all frames
    (a closed mesh has about half as many vertices as triangles)."""
    vertices = page_bytes // (BYTES_PER_VERTEX * max(1, n_frames))
    return int(max(4, min(MAX_TRIANGLES, 2 * vertices)))


def _fitted(visuals: tuple[LinkVisual, ...], n_frames: int, page_bytes: int) -> tuple:
    """The visuals decimated to :func:`mesh_budget`, then further until their vertices over
    ``n_frames`` frames take at most ``page_bytes``."""
    budget = mesh_budget(n_frames, page_bytes)
    for _ in range(8):
        kept = decimate_visuals(visuals, budget)
        size = sum(len(v.vertices) for v in kept) * n_frames * BYTES_PER_VERTEX
        if size <= page_bytes or budget <= 4:
            return kept
        budget = max(4, int(0.95 * budget * page_bytes / size))
    return kept


def _posed(parts: list[_Part], frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The parts merged and placed with the chain frames (F, n + 2, 4, 4): vertices
    (F, V, 3), faces (T, 3)."""
    vertices, faces, offset = [], [], 0
    for part in parts:
        T = frames[:, part.frame]  # (F, 4, 4)
        vertices.append(np.einsum("fij,vj->fvi", T[:, :3, :3], part.vertices) + T[:, None, :3, 3])
        faces.append(part.faces + offset)
        offset += len(part.vertices)
    return np.concatenate(vertices, axis=1), np.vstack(faces)


def _builder(vertices: np.ndarray, faces: np.ndarray, style: dict) -> TraceBuilder:
    from trackplan.report.machine_view import animated_mesh

    def build(k: int) -> dict:
        return animated_mesh(vertices[k], faces, k, style, SOLID_DECIMALS)

    return build


def _solid_style(name: str, color: str, opacity: float = 1.0, **more: object) -> dict:
    return {
        "name": name,
        "showlegend": True,
        "legendgroup": "robot",
        "color": color,
        "opacity": opacity,
        "flatshading": True,
        "lighting": {"ambient": 0.55, "diffuse": 0.8, "specular": 0.15},
        "hoverinfo": "name",
        **more,
    }


def _capsule_parts(capsules: Capsules) -> list[_Part]:
    from trackplan.report.cell_scene import capsule_mesh

    parts = []
    for c in range(len(capsules)):
        a, b = capsules.segment[c]
        vertices, faces = capsule_mesh(a, b, float(capsules.radius[c]))
        parts.append(_Part(int(capsules.frame[c]), vertices, np.asarray(faces)))
    return parts


def _capsules(case: Case) -> tuple[Capsules | None, Capsules | None]:
    """The link capsules and the tool's (None when there are none)."""
    robot = case.robot
    links = robot.collision
    tool = None
    if case.cell is not None:
        if case.cell.links is not None:
            links = case.cell.links
        if len(case.cell.tool):
            tcp = robot.n_dof + 1
            tool = Capsules(
                np.full(len(case.cell.tool), tcp),
                case.cell.tool.segment,
                case.cell.tool.radius,
                case.cell.tool.name,
            )
    if links is not None and not len(links):
        links = None
    return links, tool


def robot_look(case: Case, frames: np.ndarray, page_bytes: int = MESH_PAGE_BYTES) -> RobotLook:
    """The robot's meshes or solids at the animation frames' poses.

    Parameters
    ----------
    case
        The case (its robot, and its cell's link and tool capsules).
    frames
        The robot's chain frames at each animation frame, shape (F, n + 2, 4, 4)
        (:func:`~trackplan.report.machine_view.arm_frames`).
    page_bytes
        Most bytes of the meshes' vertices over all frames (:func:`mesh_budget`).

    Returns
    -------
    RobotLook
    """
    links, tool = _capsules(case)
    look = RobotLook("lines")
    drawn: list[np.ndarray] = []
    visuals = case.robot.visuals
    if visuals:
        look.kind = "meshes"
        kept = _fitted(visuals, len(frames), page_bytes)
        by_color: dict[str, list[LinkVisual]] = {}
        for visual in kept:
            by_color.setdefault(visual.color, []).append(visual)
        for g, (color, group) in enumerate(by_color.items()):
            parts = [_Part(v.frame, v.vertices, v.faces) for v in group]
            vertices, faces = _posed(parts, frames)
            # one legend entry shows and hides them all; hovering names the links
            name = MESHES_TRACE if g == 0 else "robot: " + ", ".join(v.name for v in group)
            style = _solid_style(name, color, showlegend=g == 0)
            look.builders.append(_builder(vertices, faces, style))
            drawn.append(vertices.reshape(-1, 3))
            look.triangles += len(faces)
        if case.cell is not None and links is not None:  # what the check measures
            vertices, faces = _posed(_capsule_parts(links), frames)
            style = _solid_style(CAPSULES_TRACE, LINK_COLOR, 0.3, visible="legendonly")
            look.builders.append(_builder(vertices, faces, {**style, "legendgroup": "capsules"}))
    elif links is not None:
        look.kind = "capsules"
        vertices, faces = _posed(_capsule_parts(links), frames)
        look.builders.append(_builder(vertices, faces, _solid_style(SOLIDS_TRACE, LINK_COLOR)))
        drawn.append(vertices.reshape(-1, 3))
        look.triangles += len(faces)
    if tool is not None:
        vertices, faces = _posed(_capsule_parts(tool), frames)
        style = _solid_style(TOOL_SOLIDS_TRACE, TOOL_COLOR)
        look.builders.append(_builder(vertices, faces, style))
        drawn.append(vertices.reshape(-1, 3))
    if drawn:
        look.points = np.vstack(drawn)
    return look
