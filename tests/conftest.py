"""Shared fixtures."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from trackplan.robots.builtin import puma560, ur5

REPO = Path(__file__).resolve().parents[1]
"""The repository root."""
CASES = REPO / "cases"
"""The shipped case files."""


@pytest.fixture(scope="session")
def cases_dir() -> Path:
    """The shipped case files' folder."""
    return CASES


@pytest.fixture(scope="session")
def puma():
    """The paper's PUMA560."""
    return puma560()


@pytest.fixture(scope="session")
def ur():
    """The built-in UR5 (no spherical wrist)."""
    return ur5()


@pytest.fixture
def rng():
    """A seeded random generator."""
    return np.random.default_rng(12345)


def replace_dh(robot, **changes):
    """``robot`` rebuilt from its DH table with some columns or limits replaced."""
    from trackplan.robots.model import DH_COLUMNS, Robot

    fields = {key: robot.dh[:, i] for i, key in enumerate(DH_COLUMNS)}
    for key in ("q_min", "q_max", "v_max", "a_max", "j_max", "T_flange_tool", "source"):
        fields[key] = getattr(robot, key)
    fields.update(changes)
    return Robot.from_dh(name=robot.name, **fields)
