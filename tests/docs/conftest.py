"""One scratch folder for the documentation's commands: a command that several checks quote
runs once per test session (per worker)."""

from __future__ import annotations

import pytest

from tests.docs.figures import Workspace


@pytest.fixture(scope="session")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Workspace:
    """Where the documented relative paths resolve; its runs are shared by the checks."""
    return Workspace(tmp_path_factory.mktemp("docs"))
