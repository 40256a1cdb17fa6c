"""The ``console`` blocks of the README and docs/*.md run as written and print what the pages
show (numbers within one unit of the last digit printed)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.docs import console
from tests.docs.figures import Workspace

PAGES = [
    page
    for page in [console.REPO / "README.md", *sorted((console.REPO / "docs").glob("*.md"))]
    if console.commands(page.read_text(encoding="utf-8"))
]


def test_pages_with_commands_are_found():
    names = [page.name for page in PAGES]
    assert {"README.md", "paper.md", "cell.md", "tool.md"} <= set(names)


def test_shown_lines_are_compared_within_the_printed_precision():
    printed = "  J = 0.6646  duration = 38.700 s\nnext line\n"
    assert console.mismatch(("  J = 0.6645  duration = 38.700 s",), printed) is None
    assert console.mismatch(("  J = 0.6643  duration = 38.700 s",), printed) is not None
    assert console.mismatch(("  J = 0.6645  duration = 38.7 s", "next..."), printed) is None
    assert console.mismatch(("next line", "  J = 0.6645  duration..."), printed) is not None


@pytest.mark.slow
@pytest.mark.parametrize("page", PAGES, ids=lambda page: page.name)
def test_console_blocks_run_as_written(page: Path, workspace: Workspace):
    for command in console.commands(page.read_text(encoding="utf-8")):
        done = workspace.run(command.line)
        assert done.returncode == command.exit_code, (command.line, done.stdout, done.stderr)
        problem = console.mismatch(command.shown, done.stdout)
        assert problem is None, f"{command.line}\n{problem}\n--- printed:\n{done.stdout}"
