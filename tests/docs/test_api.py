"""docs/api.md: its code blocks run, in order, as a user would paste them."""

from __future__ import annotations

import re

import pytest

from tests.docs import console

PAGE = console.REPO / "docs" / "api.md"


@pytest.mark.slow
def test_api_page_runs(tmp_path, monkeypatch):
    blocks = re.findall(r"^```python\n(.*?)^```", PAGE.read_text(encoding="utf-8"), re.M | re.S)
    assert len(blocks) >= 4
    monkeypatch.chdir(console.workspace(tmp_path))
    namespace: dict[str, object] = {}
    for block in blocks:
        exec(compile(block, str(PAGE), "exec"), namespace)  # the documented code, as pasted
    assert (tmp_path / "runs" / "notebook" / "trajectory.ros.yaml").is_file()


def test_front_door_names_import_from_the_top_level():
    import trackplan

    for name in (
        "load_case",
        "load_robot",
        "plan_placement",
        "optimize_placement",
        "check_trajectory",
        "CaseError",
    ):
        assert callable(getattr(trackplan, name)), name
        assert name in trackplan.__all__
