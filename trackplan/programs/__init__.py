"""Robot programs in no controller's language, built from a verified run.

:class:`~trackplan.programs.model.Program` holds the moves; the writers of
:mod:`trackplan.writers` (``krl``, ``rapid``, ``fanuc``, ``urscript``) print it in a
controller's language. See ``docs/export.md``.
"""

from trackplan.programs.build import Run, build_program
from trackplan.programs.model import (
    MOTION_FORMS,
    Budget,
    CircularMove,
    ExternalAxis,
    JointMove,
    LinearMove,
    MotionForm,
    Move,
    Part,
    Program,
    Section,
    SplineMove,
    Target,
    point_count,
    split_program,
)
from trackplan.programs.names import program_identifier

__all__ = [
    "MOTION_FORMS",
    "Budget",
    "CircularMove",
    "ExternalAxis",
    "JointMove",
    "LinearMove",
    "MotionForm",
    "Move",
    "Part",
    "Program",
    "Run",
    "Section",
    "SplineMove",
    "Target",
    "build_program",
    "point_count",
    "program_identifier",
    "split_program",
]
