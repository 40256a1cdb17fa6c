"""The documentation is self-contained: no reference outside the repository, links that
resolve, one page per topic, every page reachable from the README."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

from tests.docs import console

REPO = console.REPO
DOCS = REPO / "docs"
PAGES = sorted(DOCS.glob("*.md"))
MARKDOWN = [REPO / "README.md", *PAGES]
OTHER_BRANCHES = {"robots.md", "guarantees.md", "dynamics.md", "cell.md", "studies.md"}
"""Pages the README links that other work in progress adds to docs/."""

SKIP_DIRS = {
    ".git",
    ".venv",
    ".venv-latest",
    ".venv-lowest",
    "runs",
    "__pycache__",
    ".hypothesis",
    ".pytest_cache",
    ".ruff_cache",
    ".mypy_cache",
}
TEXT_SUFFIXES = {".py", ".md", ".yaml", ".yml", ".toml", ".cfg", ".txt", ".csv", ".html", ""}
# spelled in pieces so that this file does not match itself
OUTSIDE = ("../" + "shared", "design" + ".md", "reference" + "-paper", "/work/" + "shared")


def _repo_text_files() -> list[Path]:
    files = []
    for folder, subfolders, names in os.walk(REPO):
        # prune the skipped folders (a venv holds tens of thousands of files)
        subfolders[:] = [
            d for d in subfolders if d not in SKIP_DIRS and not d.endswith(".egg-info")
        ]
        files += [Path(folder) / n for n in names if Path(n).suffix in TEXT_SUFFIXES]
    return files


def test_no_file_refers_to_a_path_outside_the_repository():
    found = [
        f"{path.relative_to(REPO)}: {needle}"
        for path in _repo_text_files()
        for text in [path.read_text(encoding="utf-8", errors="replace")]
        for needle in OUTSIDE
        if needle in text
    ]
    assert found == []


def _slug(heading: str) -> str:
    """GitHub's anchor for a heading."""
    text = heading.strip().lower().replace("`", "")
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def _anchors(page: Path) -> set[str]:
    text = re.sub(r"```.*?```", "", page.read_text(encoding="utf-8"), flags=re.S)
    return {_slug(m) for m in re.findall(r"^#+ (.+)$", text, re.M)}


def _links(page: Path) -> list[str]:
    text = re.sub(r"```.*?```", "", page.read_text(encoding="utf-8"), flags=re.S)
    return re.findall(r"\]\(([^)\s]+)\)", text)


@pytest.mark.parametrize("page", MARKDOWN, ids=lambda p: p.name)
def test_links_resolve(page: Path):
    broken = []
    for link in _links(page):
        if re.match(r"[a-z]+:", link):
            continue
        target, _, anchor = link.partition("#")
        path = (page.parent / target).resolve() if target else page
        if path.name in OTHER_BRANCHES and not path.exists():
            continue
        if not path.exists():
            broken.append(link)
        elif anchor and path.suffix == ".md" and anchor not in _anchors(path):
            broken.append(link)
    assert broken == []


def test_one_page_per_topic_each_linked_from_the_readme():
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    titles = {}
    for page in PAGES:
        text = re.sub(r"```.*?```", "", page.read_text(encoding="utf-8"), flags=re.S)
        h1 = re.findall(r"^# (.+)$", text, re.M)
        assert len(h1) == 1, f"{page.name}: one title per page, found {h1}"
        assert h1[0] not in titles, f"{page.name} and {titles.get(h1[0])} share a topic"
        titles[h1[0]] = page.name
        assert f"(docs/{page.name})" in readme, f"docs/{page.name} is not linked from README"
