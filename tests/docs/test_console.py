"""The ``console`` blocks of docs/*.md run as written and print what the pages show."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.docs import console

PAGES = [
    page
    for page in sorted((console.REPO / "docs").glob("*.md"))
    if console.commands(page.read_text(encoding="utf-8"))
]


def test_pages_with_commands_are_found():
    assert "paper.md" in [page.name for page in PAGES]


@pytest.mark.slow
@pytest.mark.parametrize("page", PAGES, ids=lambda page: page.name)
def test_console_blocks_run_as_written(page: Path, tmp_path: Path):
    cwd = console.workspace(tmp_path)
    for command in console.commands(page.read_text(encoding="utf-8")):
        done = console.run(command, cwd)
        assert done.returncode == command.exit_code, (command.line, done.stdout, done.stderr)
        problem = console.mismatch(command.shown, done.stdout)
        assert problem is None, f"{command.line}\n{problem}\n--- printed:\n{done.stdout}"
