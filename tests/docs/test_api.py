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


def test_the_front_door_table_lists_the_top_level_names():
    import trackplan

    text = PAGE.read_text(encoding="utf-8")
    section = text[text.index("## The front door") : text.index("Results are frozen")]
    first_cells = [line.split(" | ")[0] for line in section.splitlines() if line.startswith("| `")]
    named = {name for cell in first_cells for name in re.findall(r"`(?:trackplan\.)?(\w+)", cell)}
    assert named == set(trackplan.__all__) - {"__version__"}
    for name in named:
        assert callable(getattr(trackplan, name)), name
