"""Load a part's CAD model from its file: :func:`load_part`.

``.step``/``.stp`` files are read with OpenCascade (:mod:`trackplan.io.step_part`, exact);
``.stl``/``.obj``/``.ply`` meshes with trimesh (:mod:`trackplan.io.mesh_part`, faces are
smooth regions). Both give a :class:`~trackplan.cad.part.PartModel` in metres.
"""

from __future__ import annotations

from pathlib import Path

from trackplan.cad.part import PartModel
from trackplan.errors import CaseError

STEP_SUFFIXES = (".step", ".stp")
"""File suffixes read as STEP."""
MESH_SUFFIXES = (".stl", ".obj", ".ply")
"""File suffixes read as meshes."""


def load_part(
    path: str | Path, *, scale: float | None = None, feature_angle: float = 0.349
) -> PartModel:
    """Read a part from a STEP file or a mesh.

    Parameters
    ----------
    path
        The file: ``.step``/``.stp`` (its unit is honoured) or ``.stl``/``.obj``/``.ply``.
    scale
        File units to metres, for a mesh (which carries no unit); None for STEP.
    feature_angle
        A mesh's dihedral angle (rad) above which two triangles lie in different regions.

    Raises
    ------
    CaseError
        An unknown suffix, a missing or unreadable file, or a missing optional dependency.
    """
    suffix = Path(path).suffix.lower()
    if suffix in STEP_SUFFIXES:
        from trackplan.io.step_part import read_step_part

        return read_step_part(path)
    if suffix in MESH_SUFFIXES:
        from trackplan.io.mesh_part import read_mesh_part  # type: ignore[import-not-found,unused-ignore]

        part: PartModel = read_mesh_part(path, scale=scale, feature_angle=feature_angle)
        return part
    known = ", ".join(STEP_SUFFIXES + MESH_SUFFIXES)
    raise CaseError(
        f"a part file is STEP or a mesh ({known}), got {suffix or 'no suffix'!r}", file=str(path)
    )
