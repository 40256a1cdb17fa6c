"""Sane ranges of a robot's physical inputs, in robot files and URDFs (``docs/files.md``).

Each bound lies far beyond any real robot and far below where floating point overflows, so
that a typo (``1e300``, a unit slip by 10⁹) is refused at load with one line naming the key
or the URDF attribute, instead of reaching the kinematics and dynamics as overflow.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import AfterValidator, Field
from pydantic_core import PydanticCustomError

from trackplan.io.yaml_input import MAX_COORDINATE

MAX_LENGTH = MAX_COORDINATE
"""Largest |length| or |coordinate|, m: DH d and a, origins, points, shape sizes."""
MAX_ANGLE = MAX_COORDINATE
"""Largest |angle|, rad: DH alpha and offset, joint ranges, rpy."""
MAX_RATE = 1.0e6
"""Largest joint velocity, acceleration and jerk limit, rad/s, rad/s², rad/s³."""
MIN_RATE = 1.0e-3
"""Smallest joint velocity, acceleration and jerk limit, rad/s, rad/s², rad/s³ (a slower
joint would take longer than any trajectory can hold)."""
MAX_MASS = 1.0e5
"""Largest link or payload mass, kg."""
MAX_INERTIA = 1.0e5
"""Largest |entry| of an inertia, kg·m² (motor inertias too)."""
MAX_TORQUE = 1.0e7
"""Largest torque limit, effort and |Coulomb friction|, N·m."""
MAX_GEAR_RATIO = 1.0e4
"""Largest |gear ratio|."""
MAX_VISCOUS = 1.0e6
"""Largest viscous friction, N·m·s/rad."""
MAX_MOTOR_CONSTANT = 1.0e4
"""Largest motor constant, N·m/√W."""
MAX_MESH_SCALE = 1.0e3
"""Largest |scale| of a URDF mesh along each axis."""

Length = Annotated[float, Field(ge=-MAX_LENGTH, le=MAX_LENGTH)]
Angle = Annotated[float, Field(ge=-MAX_ANGLE, le=MAX_ANGLE)]


def _at_least_min_rate(value: float) -> float:
    if value < MIN_RATE:
        raise PydanticCustomError("rate_too_small", f"expected a number ≥ {MIN_RATE:g}")
    return value


Rate = Annotated[float, Field(gt=0, le=MAX_RATE), AfterValidator(_at_least_min_rate)]
"""A joint's rate limit in [:data:`MIN_RATE`, :data:`MAX_RATE`] (one ≤ 0 reads "> 0")."""
Mass = Annotated[float, Field(le=MAX_MASS)]
"""A mass ≤ :data:`MAX_MASS`; a negative one is reported by the loaders, naming the unit."""
InertiaEntry = Annotated[float, Field(ge=-MAX_INERTIA, le=MAX_INERTIA)]
MotorInertia = Annotated[float, Field(ge=0, le=MAX_INERTIA)]
Torque = Annotated[float, Field(le=MAX_TORQUE)]
"""A torque limit ≤ :data:`MAX_TORQUE`; one ≤ 0 is reported by the loaders."""
Friction = Annotated[float, Field(ge=-MAX_TORQUE, le=MAX_TORQUE)]
GearRatio = Annotated[float, Field(ge=-MAX_GEAR_RATIO, le=MAX_GEAR_RATIO)]
Viscous = Annotated[float, Field(ge=0, le=MAX_VISCOUS)]
MotorConstant = Annotated[float, Field(gt=0, le=MAX_MOTOR_CONSTANT)]
