"""Shared fixtures."""

from __future__ import annotations

import numpy as np
import pytest

from trackplan.robots.builtin import puma560, ur5


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
