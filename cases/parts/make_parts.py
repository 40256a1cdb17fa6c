"""Make the STEP parts shipped in this folder, with OpenCascade (the ``cadquery-ocp`` binding).

Run from the repository root, in the project's venv (``make test`` installs OCP)::

    .venv/bin/python cases/parts/make_parts.py

It rewrites, in millimetres (the STEP files carry their unit; ``trackplan part`` reads them
in metres):

``pipe-plate.step``
    A pipe standing on a plate, fused: plate 300 × 300 × 10 mm (top face at z = 0, centred
    on the origin), pipe outer radius 60 mm, wall 5 mm, 150 mm high on the plate. The fillet
    seam is the circle of radius 60 mm at z = 0 about +z.
``t-joint.step``
    Two plates, fused: a base 300 × 200 × 10 mm (top at z = 0) and a web 300 × 10 × 100 mm
    standing on it along x (y in [-5, 5] mm). The two fillet seams are the lines at
    z = 0, y = ±5 mm, x in [-150, 150] mm.
``saddle.step``
    A branch on a main pipe, both solid, fused: the main pipe radius 100 mm along y
    (y in [-200, 200] mm), the branch radius 50 mm along z (z from 0 to 200 mm). The seam is
    their intersection, a B-spline: x² + y² = 50², x² + z² = 100², z > 0 (mm).

and, with ``--bench DIR``, into DIR only (1.2 MB, not shipped):

``plate-holes.step``
    A plate 600 × 450 × 10 mm (top at z = 0) with 300 through holes of radius 8 mm on a
    30 mm grid: 306 faces, for the reading benchmark (``python -m benchmarks cad`` makes it).
"""

from __future__ import annotations

import sys
from pathlib import Path

from OCP.APIHeaderSection import APIHeaderSection_MakeHeader
from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
from OCP.collections import List_TopoDS_Shape
from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
from OCP.IFSelect import IFSelect_ReturnStatus
from OCP.Interface import Interface_Static
from OCP.Message import Message, Message_Gravity
from OCP.STEPControl import STEPControl_StepModelType, STEPControl_Writer
from OCP.TCollection import TCollection_HAsciiString
from OCP.TopoDS import TopoDS_Shape

HERE = Path(__file__).resolve().parent
TIME_STAMP = "2026-12-07T00:00:00"
"""The files' header time stamp, fixed so that a rerun rewrites the same files."""


def box(x0: float, y0: float, z0: float, dx: float, dy: float, dz: float) -> TopoDS_Shape:
    """A box from its lowest corner and its sizes (mm)."""
    return BRepPrimAPI_MakeBox(gp_Pnt(x0, y0, z0), dx, dy, dz).Shape()


def cylinder(
    base: tuple[float, float, float], axis: tuple[float, float, float], radius: float, height: float
) -> TopoDS_Shape:
    """A solid cylinder from the centre of its base along an axis (mm)."""
    frame = gp_Ax2(gp_Pnt(*base), gp_Dir(*axis))
    return BRepPrimAPI_MakeCylinder(frame, radius, height).Shape()


def fuse(a: TopoDS_Shape, b: TopoDS_Shape) -> TopoDS_Shape:
    """The union of two solids."""
    op = BRepAlgoAPI_Fuse(a, b)
    op.Build()
    if not op.IsDone():
        raise RuntimeError("fuse failed")
    op.SimplifyResult()  # merge the faces the union split on one surface
    return op.Shape()


def cut(a: TopoDS_Shape, b: TopoDS_Shape) -> TopoDS_Shape:
    """a minus b."""
    op = BRepAlgoAPI_Cut(a, b)
    op.Build()
    if not op.IsDone():
        raise RuntimeError("cut failed")
    return op.Shape()


def pipe_plate() -> TopoDS_Shape:
    plate = box(-150, -150, -10, 300, 300, 10)
    pipe = cut(cylinder((0, 0, 0), (0, 0, 1), 60, 150), cylinder((0, 0, -1), (0, 0, 1), 55, 152))
    return fuse(plate, pipe)


def t_joint() -> TopoDS_Shape:
    return fuse(box(-150, -100, -10, 300, 200, 10), box(-150, -5, 0, 300, 10, 100))


def saddle() -> TopoDS_Shape:
    main = cylinder((0, -200, 0), (0, 1, 0), 100, 400)
    return fuse(main, cylinder((0, 0, 0), (0, 0, 1), 50, 200))


def plate_holes() -> TopoDS_Shape:
    plate = box(-300, -225, -10, 600, 450, 10)
    tools = List_TopoDS_Shape()
    for i in range(20):
        for j in range(15):
            tools.Append(cylinder((-285 + 30 * i, -210 + 30 * j, -11), (0, 0, 1), 8, 12))
    arguments = List_TopoDS_Shape()
    arguments.Append(plate)
    op = BRepAlgoAPI_Cut()
    op.SetArguments(arguments)
    op.SetTools(tools)
    op.Build()
    if not op.IsDone():
        raise RuntimeError("cut failed")
    return op.Shape()


def write_step(shape: TopoDS_Shape, path: Path) -> None:
    """Write a shape as a STEP AP214 file in millimetres (quietly)."""
    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Fail)
    Interface_Static.SetCVal_s("write.step.unit", "MM")
    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    writer = STEPControl_Writer()
    writer.Transfer(shape, STEPControl_StepModelType.STEPControl_AsIs)
    header = APIHeaderSection_MakeHeader(writer.Model())
    header.SetName(TCollection_HAsciiString(path.stem))
    header.SetTimeStamp(TCollection_HAsciiString(TIME_STAMP))  # the same bytes on every run
    if writer.Write(str(path)) != IFSelect_ReturnStatus.IFSelect_RetDone:
        raise RuntimeError(f"cannot write {path}")


PARTS = {"pipe-plate.step": pipe_plate, "t-joint.step": t_joint, "saddle.step": saddle}
"""The shipped parts: file name -> maker."""
BENCH_PARTS = {"plate-holes.step": plate_holes}
"""The benchmark's parts, written on demand."""


def main(argv: list[str]) -> int:
    """Write the shipped parts here, or with ``--bench DIR`` the benchmark's parts into DIR."""
    parts, folder = PARTS, HERE
    if argv[:1] == ["--bench"] and len(argv) == 2:
        parts, folder = BENCH_PARTS, Path(argv[1])
    elif argv:
        print("usage: make_parts.py [--bench DIR]", file=sys.stderr)
        return 2
    for name, make in parts.items():
        write_step(make(), folder / name)
        print(f"wrote {folder / name}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
